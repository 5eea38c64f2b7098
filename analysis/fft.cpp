#include "analysis/fft.hpp"

#include <algorithm>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>

#include <fftw3.h>

namespace robodamp::analysis {

namespace {
// FFTW's planner is not thread-safe (fftw_execute is): plans are made and destroyed under one lock.
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}
}  // namespace

RealFft::RealFft(std::size_t n) : n_(n) {
  if (n < 2 || n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::invalid_argument("RealFft: length must be 2 .. 2^31 - 1");
  in_ = fftw_alloc_real(n);
  out_ = reinterpret_cast<std::complex<double>*>(fftw_alloc_complex(n / 2 + 1));
  if (in_ == nullptr || out_ == nullptr) {
    fftw_free(in_), fftw_free(out_);
    throw std::bad_alloc();
  }
  std::fill(in_, in_ + n, 0.0);
  const std::lock_guard<std::mutex> lock(planner_mutex());
  // An out-of-place r2c plan preserves its input (FFTW's default for r2c), so the zero padding stays.
  plan_ = fftw_plan_dft_r2c_1d(static_cast<int>(n), in_, reinterpret_cast<fftw_complex*>(out_), FFTW_ESTIMATE);
  if (plan_ == nullptr) {
    fftw_free(in_), fftw_free(out_);
    throw std::runtime_error("RealFft: FFTW could not plan a transform of this length");
  }
}

RealFft::~RealFft() {
  {
    const std::lock_guard<std::mutex> lock(planner_mutex());
    fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  }
  fftw_free(in_);
  fftw_free(out_);
}

const std::complex<double>* RealFft::forward() {
  fftw_execute(static_cast<fftw_plan>(plan_));
  return out_;
}

RealInverseFft::RealInverseFft(std::size_t n) : n_(n) {
  if (n < 2 || n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::invalid_argument("RealInverseFft: length must be 2 .. 2^31 - 1");
  in_ = reinterpret_cast<std::complex<double>*>(fftw_alloc_complex(n / 2 + 1));
  out_ = fftw_alloc_real(n);
  if (in_ == nullptr || out_ == nullptr) {
    fftw_free(in_), fftw_free(out_);
    throw std::bad_alloc();
  }
  std::fill(in_, in_ + n / 2 + 1, std::complex<double>(0.0, 0.0));
  const std::lock_guard<std::mutex> lock(planner_mutex());
  plan_ = fftw_plan_dft_c2r_1d(static_cast<int>(n), reinterpret_cast<fftw_complex*>(in_), out_, FFTW_ESTIMATE);
  if (plan_ == nullptr) {
    fftw_free(in_), fftw_free(out_);
    throw std::runtime_error("RealInverseFft: FFTW could not plan a transform of this length");
  }
}

RealInverseFft::~RealInverseFft() {
  {
    const std::lock_guard<std::mutex> lock(planner_mutex());
    fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  }
  fftw_free(in_);
  fftw_free(out_);
}

const double* RealInverseFft::inverse() {
  fftw_execute(static_cast<fftw_plan>(plan_));
  return out_;
}

}  // namespace robodamp::analysis
