#include "runtime/spectrum_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rt/supervisor.hpp"

namespace robodamp::runtime {

SpectrumMonitor::SpectrumMonitor(const config::Config& cfg, SpectrumSettings s)
    : s_(s),
      teeth_(cfg.spindle.teeth),
      block_(std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(cfg.loop.rate_hz / s.display_rate_hz)))),
      fs_hz_(cfg.loop.rate_hz / static_cast<double>(block_)),
      fft_(std::make_unique<analysis::RealFft>(s.segment)),
      ring_(s.segment * (s.segments + 1) / 2, 0.0) {
  for (const auto& frf : cfg.robot.frfs)
    for (const auto& m : frf.modes) {
      const auto hz = static_cast<float>(m.natural_freq_hz);
      if (std::none_of(modes_hz_.begin(), modes_hz_.end(), [hz](float h) { return std::abs(h - hz) < 0.01F; }))
        modes_hz_.push_back(hz);
    }
  std::sort(modes_hz_.begin(), modes_hz_.end());
}

void SpectrumMonitor::on_frame(const rt::TelemetryFrame& f) {
  std::lock_guard<std::mutex> lock(m_);
  if (const auto rpm = rt::spindle_rpm_set(f)) rpm_ = *rpm;
  last_ = f;
  if (!std::isfinite(f.accel_mps2)) return;  // an invalid sample (counted by the supervisor): not on the plot
  block_sum_ += f.accel_mps2;
  if (++in_block_ < block_) return;
  ring_[head_] = block_sum_ / static_cast<double>(block_);
  head_ = (head_ + 1) % ring_.size();
  filled_ = std::min(filled_ + 1, ring_.size());
  block_sum_ = 0.0;
  in_block_ = 0;
}

std::optional<dds::SpectrumSample> SpectrumMonitor::next() {
  std::vector<double> x;
  dds::SpectrumSample out;
  {
    std::lock_guard<std::mutex> lock(m_);
    if (filled_ < ring_.size() || last_.time_s - published_s_ < s_.period_s) return std::nullopt;
    published_s_ = last_.time_s;
    x.reserve(ring_.size());
    for (std::size_t i = 0; i < ring_.size(); ++i) x.push_back(ring_[(head_ + i) % ring_.size()]);
    out.tick = last_.tick;
    out.time_s = last_.time_s;
    out.tooth_passing_hz = rpm_ * teeth_ / 60.0;
  }
  const std::size_t n = s_.segment, hop = n / 2, bins = std::min<std::size_t>(n / 2 + 1, 1024);
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  std::vector<double> psd(bins, 0.0);
  double window_power = 0.0;
  std::size_t count = 0;
  for (std::size_t start = 0; start + n <= x.size(); start += hop, ++count) {
    double* in = fft_->input();
    for (std::size_t i = 0; i < n; ++i) {
      const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n));
      in[i] = (x[start + i] - mean) * w;
      if (count == 0) window_power += w * w;
    }
    const std::complex<double>* X = fft_->forward();
    for (std::size_t k = 0; k < bins; ++k) psd[k] += std::norm(X[k]);
  }
  // One-sided density: 2 |X|^2 / (fs sum w^2), averaged over the segments.
  out.accel_asd.reserve(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    const double one_sided = (k == 0 || 2 * k == n) ? 1.0 : 2.0;
    out.accel_asd.push_back(
        static_cast<float>(std::sqrt(one_sided * psd[k] / (fs_hz_ * window_power * static_cast<double>(count)))));
  }
  out.bin_hz = fs_hz_ / static_cast<double>(n);
  out.record_s = static_cast<double>(x.size()) / fs_hz_;
  out.mode_hz = modes_hz_;
  return out;
}

}  // namespace robodamp::runtime
