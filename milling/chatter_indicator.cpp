#include "milling/chatter_indicator.hpp"

#include <algorithm>
#include <cmath>

#include "config/milling_config.hpp"

#include "analysis/fft.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

int forced_lines_per_revolution(const config::MillingConfig& job) {
  const bool runout = std::any_of(job.time_domain.runout_um.begin(), job.time_domain.runout_um.end(),
                                  [](double r) { return r != 0.0; });
  return runout ? 1 : job.tool.teeth;
}

std::vector<double> modes_above_band(const config::MillingConfig& job, const std::string& structure_name,
                                     double sample_rate_hz) {
  std::vector<double> above;
  const config::StructureConfig* structure =
      job.find_structure(structure_name.empty() ? job.structure : structure_name);
  if (structure == nullptr && structure_name.empty() && !job.structures.empty()) structure = &job.structures.front();
  if (structure != nullptr)
    for (const auto& part : structure->parts)
      for (const auto& direction : part.modes)
        for (const auto& m : direction)
          if (m.natural_freq_hz > indicator_band_max_hz(sample_rate_hz)) above.push_back(m.natural_freq_hz);
  std::sort(above.begin(), above.end());
  above.erase(std::unique(above.begin(), above.end()), above.end());
  return above;
}

ChatterMonitor::ChatterMonitor(double sample_rate_hz, ChatterIndicatorSettings s) : fs_(sample_rate_hz), s_(s) {
  ring_.assign(static_cast<std::size_t>(std::ceil(s_.max_window_s * fs_)), 0.0);
  gap_.assign(ring_.size(), 0);
  window_.reserve(ring_.size());
  off_bins_.reserve(ring_.size() / 2 + 1);
}

ChatterMonitor::~ChatterMonitor() = default;

void ChatterMonitor::push(double accel_mps2, bool fresh) {
  // A stale, missed or invalid sample keeps the time base: the last value held, marked as a gap.
  const bool gap = !fresh || !std::isfinite(accel_mps2);
  const double last = ring_[(head_ + ring_.size() - 1) % ring_.size()];
  ring_[head_] = gap ? last : accel_mps2;
  gap_[head_] = gap ? 1 : 0;
  head_ = (head_ + 1) % ring_.size();
  count_ = std::min(count_ + 1, ring_.size());
}

// The span to analyse (a full window, few held samples), oldest first, mean removed, and its RMS.
bool ChatterMonitor::fill_window(double f_sp, ChatterIndicator& out) {
  const double want_s = std::min(s_.max_window_s, std::max(s_.window_s, s_.min_revolutions / f_sp));
  const auto n = std::min(count_, static_cast<std::size_t>(want_s * fs_));
  // A full window only: after a reset (another speed) the cut's transient, which decays, fills a
  // shorter span and would look persistent.
  if (static_cast<double>(n) < std::floor(want_s * fs_) || n < 64) return false;
  // Held samples put steps into the signal, which spread over the spectrum: too many, no verdict.
  std::size_t gaps = 0;
  for (std::size_t i = 0, at = (head_ + ring_.size() - n) % ring_.size(); i < n; ++i)
    gaps += gap_[(at + i) % ring_.size()];
  out.gap_share = static_cast<double>(gaps) / static_cast<double>(n);
  if (out.gap_share > s_.max_gap_share) return false;

  // The span, oldest first, mean removed.
  window_.resize(n);
  const std::size_t start = (head_ + ring_.size() - n) % ring_.size();
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += (window_[i] = ring_[(start + i) % ring_.size()]);
  mean /= static_cast<double>(n);
  double ss = 0.0;
  for (double& v : window_) {
    v -= mean;
    ss += v * v;
  }
  out.rms_mps2 = std::sqrt(ss / static_cast<double>(n));
  if (out.rms_mps2 <= 0.0) return false;
  return true;
}

// In time: the once-per-period difference's share, its persistence over the window's eighths, the trend and growth.
void ChatterMonitor::time_measures(double f_sp, ChatterIndicator& out) const {
  const std::size_t n = window_.size();
  // Once per forced period (a revolution, or a tooth period when only the tooth harmonics are forced: chatter
  // near a spindle harmonic changes little from one revolution to the next): x(t) - x(t - one period) at
  // every sample (the forced, periodic part cancels). Its RMS over the signal's is the once-per-revolution
  // ratio; its RMS in the window's eighths, the smallest over the largest, the persistence. A decaying
  // transient (a hammer impact, a step of the cut) leaves a quiet stretch before it or after it; chatter
  // fills the window. Eighths, not quarters: `run`'s hammer hits every 2 s in a 4 s window left no quiet
  // quarter when a hit fell near a quarter's end (its ring split over two quarters), and the live
  // indicator read CHATTER on a plant that was not cutting, at every other window (a CI run's monitor).
  constexpr int kParts = 8;
  const double rev_samples = fs_ / (f_sp * s_.lines_per_revolution);
  double part_ss[kParts] = {};
  std::size_t part_n[kParts] = {};
  const auto first = static_cast<std::size_t>(std::ceil(rev_samples));
  for (std::size_t i = first; i < n; ++i) {
    const double back = static_cast<double>(i) - rev_samples;
    const auto b = static_cast<std::size_t>(back);
    const double frac = back - static_cast<double>(b);
    const double e = window_[i] - (window_[b] * (1.0 - frac) + window_[b + 1] * frac);
    const std::size_t q = std::min<std::size_t>(kParts - 1, kParts * (i - first) / (n - first));
    part_ss[q] += e * e, ++part_n[q];
  }
  double diff_ss = 0.0;
  for (const double ss_part : part_ss) diff_ss += ss_part;
  out.once_per_rev_ratio = n > first ? std::sqrt(diff_ss / static_cast<double>(n - first)) / out.rms_mps2 : 0.0;
  const auto rms_of = [](double ss_part, std::size_t count) {
    return count ? std::sqrt(ss_part / static_cast<double>(count)) : 0.0;
  };
  double p_min = INFINITY, p_max = 0.0, q_rms[4] = {0.0, 0.0, 0.0, 0.0};
  for (int p = 0; p < kParts; ++p) {
    const double r = rms_of(part_ss[p], part_n[p]);
    p_min = std::min(p_min, r), p_max = std::max(p_max, r);
  }
  for (int q = 0; q < 4; ++q) q_rms[q] = rms_of(part_ss[2 * q] + part_ss[2 * q + 1], part_n[2 * q] + part_n[2 * q + 1]);
  out.persistence = p_max > 0.0 ? p_min / p_max : 0.0;
  // Trend: the last quarter over the first. Chatter holds (a limit cycle) or grows; the marks an unstable
  // cut left fade after a change to a stable speed (the wavy surface regenerates, less each pass).
  out.trend = q_rms[0] > 0.0 ? q_rms[3] / q_rms[0] : 0.0;
  // Growing: every quarter louder than the one before by growing_step (chatter building up; an impact
  // late in the window raises only the last quarter).
  out.growing = true;
  for (int q = 1; q < 4; ++q) out.growing = out.growing && q_rms[q] > s_.growing_step * q_rms[q - 1];
}

// The spectrum: the energy away from the forced lines (by displacement), the chatter's line, the lines' SNR.
void ChatterMonitor::spectrum_measures(double f_sp, ChatterIndicator& out) {
  const std::size_t n = window_.size();
  // Spectrum (Hann), energy away from the spindle harmonics.
  if (fft_n_ != n) fft_ = std::make_unique<analysis::RealFft>(n), fft_n_ = n;
  double* in = fft_->input();
  for (std::size_t i = 0; i < n; ++i)
    in[i] = window_[i] * (0.5 - 0.5 * std::cos(kTwoPi * static_cast<double>(i) / static_cast<double>(n)));
  const std::complex<double>* X = fft_->forward();
  const double df = fs_ / static_cast<double>(n);
  // The share by displacement (each line's energy / f^2): the accelerometer weights the tooth-passing
  // harmonics by f^2 over a robot mode's chatter below them; the floor is on the acceleration.
  double total = 0.0, off = 0.0, total_a = 0.0, off_a = 0.0, best = 0.0, on_a = 0.0;
  std::size_t best_k = 0, on_bins = 0;
  off_bins_.clear();
  for (std::size_t k = 1; k < fft_->bins(); ++k) {
    const double f = static_cast<double>(k) * df;
    if (f < s_.band_min_hz || f > indicator_band_max_hz(fs_)) continue;
    const double e_a = std::norm(X[k]), e = e_a / (f * f);
    total += e, total_a += e_a;
    const double f_line = f_sp * s_.lines_per_revolution, h = std::round(f / f_line);
    if (std::abs(f - h * f_line) <= 2.0 * df + 1e-12) {
      on_a += e_a, ++on_bins;
      continue;
    }
    off += e, off_a += e_a;
    off_bins_.push_back(e_a);
    if (e > best) best = e, out.chatter_hz = f, best_k = k;
  }
  // Between the bins: the peak of a parabola through the log magnitudes of the best bin and its
  // neighbours (a Hann window's line is nearly Gaussian): a few hundredths of a bin, where the bin
  // itself is up to half a bin (0.25 Hz in a 2 s window) off.
  if (best_k > 1 && best_k + 1 < fft_->bins()) {
    const double a = std::log(std::abs(X[best_k - 1]) + 1e-300), b = std::log(std::abs(X[best_k]) + 1e-300),
                 c = std::log(std::abs(X[best_k + 1]) + 1e-300);
    const double denom = a - 2.0 * b + c;
    if (denom < 0.0) out.chatter_hz += std::clamp(0.5 * (a - c) / denom, -0.5, 0.5) * df;
  }
  if (on_bins > 0 && !off_bins_.empty()) {
    const auto mid = off_bins_.begin() + static_cast<std::ptrdiff_t>(off_bins_.size() / 2);
    std::nth_element(off_bins_.begin(), mid, off_bins_.end());
    out.forced_lines_snr = *mid > 0.0 ? on_a / static_cast<double>(on_bins) / *mid : INFINITY;
  }
  out.forced_lines = out.forced_lines_snr >= s_.forced_lines_threshold;
  out.nonharmonic_share = total > 0.0 ? off / total : 0.0;
  out.nonharmonic_rms_mps2 = total_a > 0.0 ? out.rms_mps2 * std::sqrt(off_a / total_a) : 0.0;
  if (off <= 0.0) out.chatter_hz = 0.0;
}

// One window's verdict: chatter where the vibration is not the forced lines', repeats from one period to the
// next, fills the window (or grows) and does not fade.
ChatterIndicator ChatterMonitor::evaluate(double spindle_rpm) {
  ChatterIndicator out;
  if (!(spindle_rpm > 0.0)) return out;
  const double f_sp = spindle_rpm / 60.0;
  if (!fill_window(f_sp, out)) return out;
  time_measures(f_sp, out);
  spectrum_measures(f_sp, out);
  out.valid = true;
  out.chatter = out.once_per_rev_ratio > s_.once_per_rev_threshold &&
                out.nonharmonic_share > s_.nonharmonic_threshold && out.nonharmonic_rms_mps2 > s_.floor_mps2 &&
                (out.persistence > s_.persistence_threshold || out.growing) && out.trend > s_.fading_threshold;
  return out;
}

}  // namespace robodamp::milling
