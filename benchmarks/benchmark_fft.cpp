// The FFT behind the spectral estimator, one core: the impact test's transform (a 10 s record at 5 kHz,
// 50 000 samples, zero-padded x8 to 400 000, real input) by Eigen's FFT module on kissfft (what the
// estimator used before; a new Eigen::FFT per transform as it did, and one reused with the half spectrum)
// and by FFTW (analysis::RealFft: r2c, planned once with FFTW_ESTIMATE). pocketfft is not packaged by
// Debian 12. docs/performance.md: "Main job: what each part costs".
#include <benchmark/benchmark.h>

#include <cmath>
#include <complex>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "analysis/fft.hpp"

namespace {

constexpr std::size_t kSamples = 50000, kPad = 8, kLength = kSamples * kPad;

std::vector<double> record() {
  std::vector<double> x(kLength, 0.0);
  for (std::size_t i = 0; i < kSamples; ++i) {
    const double t = static_cast<double>(i) / 5000.0;
    x[i] = std::exp(-1.2 * t) * std::sin(57.8 * t);
  }
  return x;
}

void BM_KissFftNewEachTime(benchmark::State& state) {
  const std::vector<double> x = record();
  std::vector<std::complex<double>> out;
  for (auto _ : state) {
    Eigen::FFT<double> fft;
    fft.fwd(out, x);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_KissFftNewEachTime)->Unit(benchmark::kMillisecond);

void BM_KissFftReusedHalfSpectrum(benchmark::State& state) {
  const std::vector<double> x = record();
  std::vector<std::complex<double>> out;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  for (auto _ : state) {
    fft.fwd(out, x);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_KissFftReusedHalfSpectrum)->Unit(benchmark::kMillisecond);

void BM_FftwRealPlannedOnce(benchmark::State& state) {
  const std::vector<double> x = record();
  robodamp::analysis::RealFft fft(kLength);
  std::copy(x.begin(), x.end(), fft.input());
  for (auto _ : state) benchmark::DoNotOptimize(fft.forward());
}
BENCHMARK(BM_FftwRealPlannedOnce)->Unit(benchmark::kMillisecond);

// Planning cost, paid once per estimator.
void BM_FftwPlan(benchmark::State& state) {
  for (auto _ : state) {
    robodamp::analysis::RealFft fft(kLength);
    benchmark::DoNotOptimize(fft.input());
  }
}
BENCHMARK(BM_FftwPlan)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
