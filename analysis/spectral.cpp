#include "analysis/spectral.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robodamp::analysis {

FrfAccumulator::FrfAccumulator(std::size_t segment_samples, double fs_hz, int zero_pad, Window window, double max_hz,
                               std::size_t outputs)
    : n_(segment_samples), nfft_(segment_samples * static_cast<std::size_t>(std::max(zero_pad, 1))), fs_hz_(fs_hz) {
  if (n_ < 8) throw std::invalid_argument("FrfAccumulator: segments need at least 8 samples");
  bins_ =
      std::min(nfft_ / 2 + 1, static_cast<std::size_t>(std::floor(max_hz / (fs_hz / static_cast<double>(nfft_)))) + 1);
  window_.assign(n_, 1.0);
  if (window == Window::kHann)
    for (std::size_t i = 0; i < n_; ++i)
      window_[i] = 0.5 - 0.5 * std::cos(kTwoPi * static_cast<double>(i) / static_cast<double>(n_));
  sxy_.assign(outputs, std::vector<std::complex<double>>(bins_, 0.0));
  sxx_.assign(bins_, 0.0);
  syy_.assign(outputs, std::vector<double>(bins_, 0.0));
  fft_ = std::make_unique<RealFft>(nfft_);
  fx_.assign(bins_, 0.0);
  fy_.assign(bins_, 0.0);
}

void FrfAccumulator::spectrum(const std::vector<double>& v, std::vector<std::complex<double>>& out) {
  double* in = fft_->input();  // samples n_.. stay zero (the padding)
  for (std::size_t i = 0; i < n_; ++i) in[i] = v[i] * window_[i];
  const std::complex<double>* x = fft_->forward();
  std::copy(x, x + bins_, out.begin());
}

void FrfAccumulator::add(const std::vector<double>& x, const std::vector<std::vector<double>>& ys) {
  if (ys.size() != sxy_.size()) throw std::invalid_argument("FrfAccumulator::add: wrong number of outputs");
  if (x.size() != n_) throw std::invalid_argument("FrfAccumulator::add: segment length mismatch");
  for (const auto& y : ys)
    if (y.size() != n_) throw std::invalid_argument("FrfAccumulator::add: segment length mismatch");
  spectrum(x, fx_);
  for (std::size_t k = 0; k < bins_; ++k) sxx_[k] += std::norm(fx_[k]);
  for (std::size_t o = 0; o < ys.size(); ++o) {
    spectrum(ys[o], fy_);
    for (std::size_t k = 0; k < bins_; ++k) {
      sxy_[o][k] += std::conj(fx_[k]) * fy_[k];
      syy_[o][k] += std::norm(fy_[k]);
    }
  }
  ++averages_;
}

FrfEstimate FrfAccumulator::result(std::size_t o) const {
  FrfEstimate e;
  e.averages = averages_;
  e.resolution_hz = fs_hz_ / static_cast<double>(n_);
  e.grid_hz = fs_hz_ / static_cast<double>(nfft_);
  for (std::size_t k = 0; k < bins_; ++k) {
    e.f_hz.push_back(static_cast<double>(k) * e.grid_hz);
    e.h1.push_back(sxx_[k] > 0.0 ? sxy_[o][k] / sxx_[k] : 0.0);
    const double den = sxx_[k] * syy_[o][k];
    e.coherence.push_back(den > 0.0 ? std::norm(sxy_[o][k]) / den : 0.0);
    e.sxx.push_back(sxx_[k] / std::max(averages_, 1));
    e.syy.push_back(syy_[o][k] / std::max(averages_, 1));
  }
  return e;
}

FrfEstimate welch_frf(const std::vector<double>& x, const std::vector<double>& y, double fs_hz,
                      std::size_t segment_samples, double overlap, double max_hz) {
  if (x.size() != y.size() || x.size() < segment_samples)
    throw std::invalid_argument("welch_frf: records must be equally long and hold one segment");
  FrfAccumulator acc(segment_samples, fs_hz, 1, Window::kHann, max_hz);
  const auto hop = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::lround((1.0 - overlap) * static_cast<double>(segment_samples))));
  for (std::size_t start = 0; start + segment_samples <= x.size(); start += hop)
    acc.add(std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(start),
                                x.begin() + static_cast<std::ptrdiff_t>(start + segment_samples)),
            std::vector<double>(y.begin() + static_cast<std::ptrdiff_t>(start),
                                y.begin() + static_cast<std::ptrdiff_t>(start + segment_samples)));
  return acc.result();
}

void accelerance_to_receptance(FrfEstimate& e) {
  for (std::size_t k = 0; k < e.f_hz.size(); ++k) {
    const double w = kTwoPi * e.f_hz[k];
    e.h1[k] = w > 0.0 ? e.h1[k] / (-w * w) : 0.0;
  }
}

}  // namespace robodamp::analysis
