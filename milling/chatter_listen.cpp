#include "milling/chatter_listen.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "analysis/fft.hpp"
#include "analysis/spectral.hpp"

namespace robodamp::milling {

namespace {

std::string fmt(const char* format, auto... args) {
  char b[256];
  std::snprintf(b, sizeof b, format, args...);
  return b;
}

// Non-finite samples held at the last finite value (their places returned); the mean removed.
std::vector<bool> clean(std::vector<double>& x, ListenReport& r) {
  std::vector<bool> gap(x.size(), false);
  std::size_t bad = 0;
  double last = 0.0, sum = 0.0, sq = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) x[i] = last, gap[i] = true, ++bad;
    last = x[i], sum += x[i], sq += x[i] * x[i];
  }
  const double n = static_cast<double>(x.size()), mean = sum / n, rms = std::sqrt(std::max(0.0, sq / n - mean * mean));
  if (bad > 0)
    r.warnings.push_back(
        fmt("%zu samples are not finite (dropouts): held at the last value; a window with more than 1 %% of them "
            "gets no verdict",
            bad));
  if (std::abs(mean) > 0.1 * rms && rms > 0.0)
    r.warnings.push_back(
        fmt("a DC offset of %.4g (%.0f %% of the signal's RMS) was removed", mean, 100.0 * std::abs(mean) / rms));
  for (double& v : x) v -= mean;
  // Clipping: runs of 3 or more samples at the record's extreme value.
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  std::size_t clipped = 0;
  for (std::size_t i = 2; i < x.size(); ++i)
    for (const double edge : {*lo, *hi})
      if (x[i] == edge && x[i - 1] == edge && x[i - 2] == edge) ++clipped;
  if (clipped > x.size() / 1000)
    r.warnings.push_back(
        fmt("clipped: %.2f %% of the samples sit at the recorder's limit (%.4g / %.4g): the vibration there is "
            "larger than recorded",
            100.0 * static_cast<double>(clipped) / n, *lo + mean, *hi + mean));
  return gap;
}

// An anti-aliased decimation by d (windowed-sinc low-pass at 0.4 of the new rate, Hann window); a kept
// sample is a gap when a held one lies within its filter's span.
void decimate(std::vector<double>& x, std::vector<bool>& gap, std::size_t d) {
  if (d <= 1) return;
  const std::size_t half = 8 * d;
  std::vector<double> h(2 * half + 1);
  double sum = 0.0;
  for (std::size_t j = 0; j < h.size(); ++j) {
    const double t = static_cast<double>(j) - static_cast<double>(half), fc = 0.4 / static_cast<double>(d);
    const double sinc = t == 0.0 ? 2.0 * fc : std::sin(2.0 * M_PI * fc * t) / (M_PI * t);
    h[j] = sinc * 0.5 * (1.0 - std::cos(2.0 * M_PI * static_cast<double>(j) / static_cast<double>(h.size() - 1)));
    sum += h[j];
  }
  std::vector<double> y;
  std::vector<bool> g;
  for (std::size_t m = 0; m * d < x.size(); ++m) {
    double acc = 0.0;
    bool held = false;
    for (std::size_t j = 0; j < h.size(); ++j) {
      const long i = static_cast<long>(m * d + j) - static_cast<long>(half);
      const auto k = static_cast<std::size_t>(std::clamp(i, 0L, static_cast<long>(x.size()) - 1));
      acc += h[j] * x[k];
      held = held || (gap[k] && std::abs(i - static_cast<long>(m * d)) <= static_cast<long>(d));
    }
    y.push_back(acc / sum), g.push_back(held);
  }
  x = std::move(y), gap = std::move(g);
}

double line(const std::vector<double>& p, double df, double f) {
  const auto k = static_cast<std::size_t>(std::lround(f / df));
  double v = 0.0;
  for (std::size_t j = k > 0 ? k - 1 : 0; j <= k + 1 && j < p.size(); ++j) v = std::max(v, p[j]);
  return v;
}

// Half-window Hann spectra of the analysed signal, from two bins up to max_hz, in at most 400 rows spaced
// evenly in log frequency (each the largest bin within it): a robot's 5-30 Hz chatter and the spindle harmonic
// half a hertz beside it fall on rows of their own, where rows of equal width (2.5 Hz up to 1 kHz) merged them.
void spectrogram(const std::vector<double>& x, double rate_hz, std::size_t n, double max_hz, ListenReport& r) {
  const std::size_t hop = std::max<std::size_t>(n / 2, 1), len = hop * 2;
  analysis::RealFft fft(len);
  const double df = rate_hz / static_cast<double>(len);
  const auto bins = std::min(fft.bins(), static_cast<std::size_t>(max_hz / df) + 1);
  // Row g holds the bins [first[g], first[g + 1]): at least one each.
  std::vector<std::size_t> first{2};
  const double ratio = std::pow(static_cast<double>(bins) / 2.0, 1.0 / 400.0);
  for (double edge = 2.0 * ratio; first.back() < bins; edge *= ratio)
    if (const auto k = std::min(bins, static_cast<std::size_t>(std::ceil(edge))); k > first.back()) first.push_back(k);
  for (std::size_t g = 0; g + 1 < first.size(); ++g)
    r.spectrogram_hz.push_back(std::sqrt(static_cast<double>(first[g]) * static_cast<double>(first[g + 1] - 1)) * df);
  for (std::size_t b = 0; b + len <= x.size(); b += hop) {
    for (std::size_t i = 0; i < len; ++i)
      fft.input()[i] =
          x[b + i] * 0.5 * (1.0 - std::cos(2.0 * M_PI * static_cast<double>(i) / static_cast<double>(len)));
    const std::complex<double>* X = fft.forward();
    std::vector<double> col;
    for (std::size_t g = 0; g + 1 < first.size(); ++g) {
      double m = 0.0;
      for (std::size_t k = first[g]; k < first[g + 1]; ++k)
        m = std::max(m, std::abs(X[k]) * 4.0 / static_cast<double>(len));
      col.push_back(20.0 * std::log10(std::max(m, 1e-12)));
    }
    r.spectrogram_t_s.push_back((static_cast<double>(b) + 0.5 * static_cast<double>(len)) / rate_hz);
    r.spectrogram_db.push_back(std::move(col));
  }
}

// The onset to a revolution: the vibration the spindle does not repeat, x(t) - x(t - one revolution)
// (linear interpolation), RMS per revolution; walking back from the first chatter window's start, the
// start of the run of revolutions above the floor that reaches it. No floor: the window's start.
double refined_onset(const std::vector<double>& x, double rate_hz, double rpm, double window_start_s, double floor) {
  if (!(floor > 0.0)) return window_start_s;
  const double rev = rate_hz * 60.0 / rpm;
  const auto per = static_cast<std::size_t>(std::ceil(rev));
  auto rms_from = [&](std::size_t b) {
    double ss = 0.0;
    for (std::size_t i = b; i < b + per; ++i) {
      const double back = static_cast<double>(i) - rev;
      const auto j = static_cast<std::size_t>(std::floor(back));
      const double w = back - static_cast<double>(j);
      const double d = x[i] - ((1.0 - w) * x[j] + w * x[j + 1]);
      ss += d * d;
    }
    return std::sqrt(ss / static_cast<double>(per));
  };
  auto b = static_cast<std::size_t>(window_start_s * rate_hz);
  // Not refined where the window starts less than a revolution into the recording (no revolution before it to
  // compare with: x(t - one revolution) would read before the first sample) or the floor is not crossed there.
  if (b < per + 1 || b + per >= x.size() || rms_from(b) <= floor) return window_start_s;
  while (b >= per + static_cast<std::size_t>(std::ceil(rev)) + 1 && rms_from(b - per) > floor) b -= per;
  return static_cast<double>(b) / rate_hz;
}

}  // namespace

const char* to_string(WindowVerdict v) {
  switch (v) {
    case WindowVerdict::kStable:
      return "stable";
    case WindowVerdict::kChatter:
      return "chatter";
    case WindowVerdict::kNoSignal:
      return "not enough signal";
  }
  return "";
}

std::optional<RpmEstimate> estimate_rpm(const std::vector<double>& x, double rate_hz, int teeth, double rpm_min,
                                        double rpm_max) {
  const double top = 0.4 * rate_hz;
  const auto segment = static_cast<std::size_t>(std::min<double>(static_cast<double>(x.size()), 8.0 * rate_hz));
  if (segment < 64) return std::nullopt;
  const analysis::FrfEstimate e = analysis::welch_frf(x, x, rate_hz, segment, 0.5, top);
  const std::vector<double>& p = e.sxx;
  if (p.size() < 8) return std::nullopt;
  const double df = e.f_hz[1] - e.f_hz[0];
  double total = 0.0;
  for (std::size_t k = 1; k < p.size(); ++k) total += p[k];
  // Each harmonic's prominence over the spectrum halfway to the next, in dB (0 .. 30): a comb of many
  // lines outscores one loud line (the chatter itself).
  const double eps = 1e-12 * total;
  auto score = [&](double f) {
    double s = 0.0;
    for (int k = 1; k * f < top && k <= 40; ++k)
      s += std::clamp(10.0 * std::log10((line(p, df, k * f) + eps) / (line(p, df, (k - 0.5) * f) + eps)), 0.0, 30.0);
    return s;
  };
  // The comb fundamentals over the range (spindle or tooth frequencies); the highest within 85 % of the
  // best (a comb at half the frequency holds the same lines).
  const double f_lo = rpm_min / 60.0, f_hi = std::min(rpm_max / 60.0 * teeth, top / 3.0);
  std::vector<std::pair<double, double>> scored;
  double best = 0.0;
  for (double f = f_lo; f <= f_hi; f *= 1.0 + 0.1 * df / std::max(f * 40.0, df)) {
    const double s = score(f);
    scored.emplace_back(f, s), best = std::max(best, s);
  }
  if (!(best > 0.0)) return std::nullopt;
  double f0 = 0.0;
  for (const auto& [f, s] : scored)
    if (s >= 0.85 * best) f0 = std::max(f0, f);
  double on_comb = 0.0;
  for (int k = 1; k * f0 < top && k <= 40; ++k) on_comb += line(p, df, k * f0);
  RpmEstimate out;
  out.comb_share = std::min(1.0, on_comb / total);
  // The spindle's own line or the tooth's: a tooth-passing line at N x f0 standing out above the lines
  // below it says f0 is the spindle (runout lines); else f0 is the tooth-passing frequency.
  double below = 0.0;
  for (int k = 1; k < teeth; ++k) below = std::max(below, line(p, df, k * f0));
  const bool spindle = teeth > 1 && teeth * f0 < top && line(p, df, teeth * f0) > below;
  out.rpm = 60.0 * (spindle ? f0 : f0 / teeth);
  out.how =
      spindle
          ? fmt("estimated from the spindle's harmonics (%.4g Hz; its harmonic %d is the tooth-passing line), %.0f %% "
                "of the spectrum on the comb",
                f0, teeth, 100.0 * out.comb_share)
          : fmt("estimated from the tooth-passing harmonics (%.4g Hz for %d teeth), %.0f %% of the spectrum on the "
                "comb",
                f0, teeth, 100.0 * out.comb_share);
  if (out.rpm < rpm_min || out.rpm > rpm_max) return std::nullopt;
  return out;
}

std::vector<SpeedToTry> pockets(double chatter_hz, int teeth, double rpm_now, double rpm_min, double rpm_max) {
  std::vector<SpeedToTry> out;
  for (int k = 1; k <= 200; ++k) {
    const double rpm = 60.0 * chatter_hz / (teeth * k);
    if (rpm < rpm_min) break;
    if (rpm <= rpm_max) out.push_back({rpm, k});
  }
  std::sort(out.begin(), out.end(), [&](const SpeedToTry& a, const SpeedToTry& b) {
    return std::abs(a.rpm - rpm_now) < std::abs(b.rpm - rpm_now);
  });
  if (out.size() > 5) out.resize(5);
  return out;
}

namespace {

// The speed the recording is judged at (r.rpm, r.rpm_source): given, the recording's own (returned per kept
// sample after decimating by d, for each window's), or estimated from the analysed signal x.
std::vector<double> listening_speed(const RecordedSignal& sig, const ListenSettings& s, const std::vector<double>& x,
                                    std::size_t d, ListenReport& r) {
  std::vector<double> rpm_at;
  for (std::size_t i = 0; i < sig.rpm.size() && !s.rpm; i += d) rpm_at.push_back(sig.rpm[i]);
  if (s.rpm) {
    r.rpm = *s.rpm, r.rpm_source = "given";
  } else if (!rpm_at.empty()) {
    std::vector<double> sorted = rpm_at;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    r.rpm = sorted[sorted.size() / 2], r.rpm_source = "from " + sig.rpm_from + " (median; each window at its own)";
  } else {
    const auto e = estimate_rpm(x, r.analysed_rate_hz, s.teeth, s.rpm_min, s.rpm_max);
    if (!e) throw std::invalid_argument(sig.source + ": no spindle speed found in the signal's harmonics; give --rpm");
    r.rpm = e->rpm, r.rpm_source = e->how;
  }
  return rpm_at;
}

}  // namespace

namespace {

// The window of n samples from b: its speed (rpm_at's median over it, else rpm), its indicator and verdict.
ListenWindow judge_window(ChatterMonitor& monitor, const std::vector<double>& x, const std::vector<bool>& gap,
                          const std::vector<double>& rpm_at, std::size_t b, std::size_t n, double rate_hz, double rpm) {
  monitor.reset();
  for (std::size_t i = b; i < b + n; ++i) monitor.push(x[i], !gap[i]);
  ListenWindow w;
  w.start_s = static_cast<double>(b) / rate_hz, w.end_s = static_cast<double>(b + n) / rate_hz;
  w.rpm = rpm;
  // The speed that held over the window (the median: a change mid-window shows as the larger part).
  if (rpm_at.size() >= b + n) {
    std::vector<double> in(rpm_at.begin() + static_cast<long>(b), rpm_at.begin() + static_cast<long>(b + n));
    std::nth_element(in.begin(), in.begin() + static_cast<long>(in.size() / 2), in.end());
    w.rpm = in[in.size() / 2];
  }
  w.indicator = w.rpm > 0.0 ? monitor.evaluate(w.rpm) : ChatterIndicator{};
  w.rms = w.indicator.rms_mps2, w.chatter_share = w.indicator.nonharmonic_share;
  // Not enough signal: no verdict (dropouts, not a full window), or no cut heard (neither chatter nor the
  // spindle's forced lines above the noise: an air cut). A quiet cut whose lines stand out is stable.
  if (!w.indicator.valid || (!w.indicator.chatter && !w.indicator.forced_lines))
    w.verdict = WindowVerdict::kNoSignal;
  else
    w.verdict = w.indicator.chatter ? WindowVerdict::kChatter : WindowVerdict::kStable;
  return w;
}

}  // namespace

ListenReport listen(const RecordedSignal& sig, const ListenSettings& s) {
  if (s.teeth < 1 || s.teeth > 32)
    throw std::invalid_argument("teeth = " + std::to_string(s.teeth) + ": allowed 1 .. 32");
  if (!(sig.rate_hz > 0.0)) throw std::invalid_argument(sig.source + ": no sample rate");
  ListenReport r;
  r.rate_hz = sig.rate_hz, r.samples = sig.samples.size();
  const double duration_s = static_cast<double>(sig.samples.size()) / sig.rate_hz;
  if (duration_s < s.window_s)
    throw std::invalid_argument(sig.source + fmt(": %.3g s recorded; one window needs %.3g s", duration_s, s.window_s));
  if (sig.rate_hz < 2.0 * s.indicator.band_min_hz * 4.0)
    throw std::invalid_argument(sig.source + fmt(": %.4g Hz is too low a rate for a chatter band from %.3g Hz",
                                                 sig.rate_hz, s.indicator.band_min_hz));
  std::vector<double> x = sig.samples;
  std::vector<bool> gap = clean(x, r);
  const auto d = static_cast<std::size_t>(std::max(1.0, std::floor(sig.rate_hz / (2.5 * s.max_hz))));
  decimate(x, gap, d);
  r.analysed_rate_hz = sig.rate_hz / static_cast<double>(d);
  const std::vector<double> rpm_at = listening_speed(sig, s, x, d, r);
  const double tooth_hz = s.teeth * r.rpm / 60.0;
  if (tooth_hz > 0.45 * r.analysed_rate_hz)
    r.warnings.push_back(
        fmt("the tooth-passing frequency (%.4g Hz) is above the analysed band (%.4g Hz): only the spindle's "
            "lower harmonics are seen",
            tooth_hz, 0.45 * r.analysed_rate_hz));
  // A band narrower than the recording's: a chatter above it is not seen (docs/milling.md, "One chatter
  // frequency": the industrial robot's 5.5 kHz chatter read stable in a 1 kHz band).
  if (0.5 * sig.rate_hz > 1.5 * s.max_hz)
    r.warnings.push_back(
        fmt("analysed up to %.4g Hz of the %.4g Hz the recording holds (--max-hz): a chatter above it (a spindle or "
            "tool mode's) is not seen",
            s.max_hz, 0.5 * sig.rate_hz));
  ChatterIndicatorSettings is = s.indicator;
  is.window_s = s.window_s, is.max_window_s = std::max(is.max_window_s, s.window_s);
  if (s.floor)
    is.floor_mps2 = *s.floor;
  else if (!sig.acceleration_mps2) {
    is.floor_mps2 = 0.0;
    r.warnings.push_back("the signal is not an acceleration in m/s^2 (" +
                         (sig.unit.empty() ? std::string("no unit") : sig.unit) +
                         "): no floor, so noise alone may read as chatter; give --floor in its unit");
  }
  ChatterMonitor monitor(r.analysed_rate_hz, is);
  const auto n = static_cast<std::size_t>(std::floor(s.window_s * r.analysed_rate_hz));
  std::vector<double> found;
  double onset_rpm = r.rpm;
  for (std::size_t b = 0; b + n <= x.size(); b += n) {
    ListenWindow w = judge_window(monitor, x, gap, rpm_at, b, n, r.analysed_rate_hz, r.rpm);
    if (w.verdict == WindowVerdict::kChatter) {
      w.chatter_hz = w.indicator.chatter_hz, found.push_back(w.chatter_hz);
      if (!r.onset_s) r.onset_s = w.start_s, onset_rpm = w.rpm;
      r.end_s = w.end_s;
    }
    r.windows.push_back(w);
  }
  if (r.onset_s) r.onset_s = refined_onset(x, r.analysed_rate_hz, onset_rpm, *r.onset_s, is.floor_mps2);
  spectrogram(x, r.analysed_rate_hz, n, std::min(s.max_hz, 0.5 * r.analysed_rate_hz), r);
  if (!found.empty()) {
    std::nth_element(found.begin(), found.begin() + static_cast<long>(found.size() / 2), found.end());
    r.chatter_hz = found[found.size() / 2];
    double rpm_chatter = r.rpm;  // the speed the cut chattered at: its last chatter window's
    for (const auto& w : r.windows)
      if (w.verdict == WindowVerdict::kChatter) rpm_chatter = w.rpm;
    r.speeds = pockets(r.chatter_hz, s.teeth, rpm_chatter, s.rpm_min, s.rpm_max);
  }
  return r;
}

}  // namespace robodamp::milling
