// FRF estimation from sampled input/output records: the H1 estimator (cross spectrum over input auto
// spectrum) with ordinary coherence, averaged over segments. Segments are either whole impact records
// (rectangular window, zero-padded: a record whose response has decayed is transformed exactly, so the
// padding interpolates the true FRF between the 1/T bins) or Welch's overlapping Hann segments of a
// long record. Off the real-time path; real-input FFTs by FFTW (analysis/fft.hpp), one plan per accumulator.
#pragma once

#include <complex>
#include <cstddef>
#include <memory>
#include <vector>

#include "analysis/fft.hpp"

namespace robodamp::analysis {

enum class Window { kRectangular, kHann };

struct FrfEstimate {
  std::vector<double> f_hz;
  std::vector<std::complex<double>> h1;  // output per input
  std::vector<double> coherence;         // 0..1
  std::vector<double> sxx, syy;          // averaged auto spectra (arbitrary common scale)
  int averages{0};
  double resolution_hz{0.0};  // 1 / segment length
  double grid_hz{0.0};        // bin spacing after zero padding
};

// One input, any number of outputs (the input's spectrum is computed once per segment).
class FrfAccumulator {
 public:
  // Bins up to max_hz are kept.
  FrfAccumulator(std::size_t segment_samples, double fs_hz, int zero_pad, Window window, double max_hz,
                 std::size_t outputs = 1);
  // x and every y: segment_samples each.
  void add(const std::vector<double>& x, const std::vector<std::vector<double>>& ys);
  void add(const std::vector<double>& x, const std::vector<double>& y) { add(x, std::vector<std::vector<double>>{y}); }
  [[nodiscard]] FrfEstimate result(std::size_t output = 0) const;
  [[nodiscard]] int averages() const { return averages_; }

 private:
  // The first bins_ bins of the windowed, zero-padded segment's transform, into out.
  void spectrum(const std::vector<double>& v, std::vector<std::complex<double>>& out);
  std::size_t n_, nfft_, bins_;
  std::unique_ptr<RealFft> fft_;  // planned once
  std::vector<std::complex<double>> fx_, fy_;
  double fs_hz_;
  std::vector<double> window_;
  std::vector<std::vector<std::complex<double>>> sxy_;
  std::vector<double> sxx_;
  std::vector<std::vector<double>> syy_;
  int averages_{0};
};

// Welch's method over a long record: Hann segments with the given overlap (0..0.9).
[[nodiscard]] FrfEstimate welch_frf(const std::vector<double>& x, const std::vector<double>& y, double fs_hz,
                                    std::size_t segment_samples, double overlap, double max_hz);

// Receptance from an accelerance estimate: H / (-w^2) (bins at 0 Hz are left at 0).
void accelerance_to_receptance(FrfEstimate& e);

}  // namespace robodamp::analysis
