// `robodamp chatter`'s analysis of a long recording (docs/performance.md: listening to a recorded cut): 60 s at 48 kHz
// (2.88 million samples), the spindle speed estimated, 30 windows judged by the live indicator's code.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "milling/chatter_listen.hpp"

namespace {

robodamp::milling::RecordedSignal recording(double rate_hz, double duration_s) {
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  robodamp::milling::RecordedSignal s;
  s.source = "benchmark", s.rate_hz = rate_hz;
  const double f_sp = 700.0 / 60.0;
  for (int i = 0; i < static_cast<int>(duration_s * rate_hz); ++i) {
    const double t = i / rate_hz;
    double v = noise(rng);
    for (int k = 1; k <= 30; ++k)
      v += (k % 3 == 0 ? 0.4 : 0.05) / std::sqrt(k) * std::sin(2.0 * M_PI * k * f_sp * t + 0.7 * k);
    if (t > 30.0) v += std::min(0.05 * std::exp(3.0 * (t - 30.0)), 1.5) * std::sin(2.0 * M_PI * 17.3 * t);
    s.samples.push_back(v);
  }
  return s;
}

void BM_Listen60sAt48kHz(benchmark::State& state) {
  const robodamp::milling::RecordedSignal s = recording(48000.0, 60.0);
  robodamp::milling::ListenSettings ls;
  ls.teeth = 3, ls.rpm_min = 300.0, ls.rpm_max = 3000.0;
  for (auto _ : state) benchmark::DoNotOptimize(robodamp::milling::listen(s, ls));
}
BENCHMARK(BM_Listen60sAt48kHz)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
