// The real-input discrete Fourier transform of one fixed length, on FFTW (r2c, planned once with
// FFTW_ESTIMATE so that the algorithm, and therefore every bit of the result, is the same on every run and
// in every thread). Off the real-time path: construction plans and allocates; forward() does neither.
// One object per thread (the buffers are the object's); planning is serialised inside.
#pragma once

#include <complex>
#include <cstddef>

namespace robodamp::analysis {

class RealFft {
 public:
  explicit RealFft(std::size_t n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] std::size_t bins() const { return n_ / 2 + 1; }
  // The input buffer (size() samples) to fill before forward().
  [[nodiscard]] double* input() { return in_; }
  // X[k] = sum_n x[n] e^{-2 pi i k n / N} for k < bins() (the rest follows by conjugate symmetry).
  // Leaves input() as it was.
  [[nodiscard]] const std::complex<double>* forward();

 private:
  std::size_t n_;
  double* in_{nullptr};
  std::complex<double>* out_{nullptr};
  void* plan_{nullptr};
};

// The inverse: x[n] = sum_k X[k] e^{2 pi i k n / N} over all N bins (the bins above N / 2 the conjugates of
// those below), unnormalised as FFTW's c2r (divide by N for the inverse of forward()). Same rules as RealFft.
class RealInverseFft {
 public:
  explicit RealInverseFft(std::size_t n);
  ~RealInverseFft();
  RealInverseFft(const RealInverseFft&) = delete;
  RealInverseFft& operator=(const RealInverseFft&) = delete;

  [[nodiscard]] std::size_t size() const { return n_; }
  [[nodiscard]] std::size_t bins() const { return n_ / 2 + 1; }
  // The spectrum (bins() values) to fill before inverse(); inverse() overwrites it.
  [[nodiscard]] std::complex<double>* input() { return in_; }
  [[nodiscard]] const double* inverse();

 private:
  std::size_t n_;
  std::complex<double>* in_{nullptr};
  double* out_{nullptr};
  void* plan_{nullptr};
};

}  // namespace robodamp::analysis
