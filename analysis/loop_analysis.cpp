// The analyses on a loop model (analysis/loop_model.hpp): the largest stable gain, the margins, the FRFs'
// improvements, the gain sweep and the whole analysis of a configuration.
#include "analysis/loop_model.hpp"

#include "analysis/gain_path.hpp"
#include "analysis/quiet_command.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "control/controller.hpp"
#include "sim_plant/state_space.hpp"
#include "units/units.hpp"

namespace robodamp::analysis {
namespace {
// max_stable_gain starts its scan at its last step below this share of the margins' crossing gain: the step
// is 10 %, so two or three steps before the crossing, the sweep's bisected crossings being far finer.
constexpr double kCrossingShare = 0.8;
}  // namespace

std::vector<double> linear_grid(double lo, double hi, double step) {
  std::vector<double> g;
  const auto n = static_cast<std::size_t>(std::ceil((hi - lo) / step));
  for (std::size_t i = 0; i <= n; ++i) g.push_back(std::min(hi, lo + static_cast<double>(i) * step));
  return g;
}

Peak find_peak(const std::vector<double>& grid, const std::vector<double>& v,
               const std::function<double(double)>& refine) {
  Peak best{grid.front(), v.front()};
  const std::size_t n = grid.size();
  for (std::size_t i = 0; i < n; ++i) {
    const bool local = (i == 0 || v[i] >= v[i - 1]) && (i + 1 == n || v[i] >= v[i + 1]);
    if (!local || v[i] < 0.5 * best.magnitude) continue;
    Peak p{grid[i], v[i]};
    if (i > 0 && i + 1 < n) {  // golden-section search between the neighbours
      const double r = 0.5 * (std::sqrt(5.0) - 1.0);
      double a = grid[i - 1], b = grid[i + 1];
      double c = b - r * (b - a), d = a + r * (b - a), fc = refine(c), fd = refine(d);
      for (int it = 0; it < 40 && b - a > 1e-7; ++it) {
        if (fc > fd) {
          b = d, d = c, fd = fc, c = b - r * (b - a), fc = refine(c);
        } else {
          a = c, c = d, fc = fd, d = a + r * (b - a), fd = refine(d);
        }
      }
      const double fm = 0.5 * (a + b), vm = refine(fm);
      if (vm > p.magnitude) p = {fm, vm};
    }
    if (p.magnitude > best.magnitude) best = p;
  }
  return best;
}

std::optional<double> max_stable_gain(const LoopModel& m, int polarity, std::optional<double> crossing_gain_ns_per_m) {
  const GainPath path(m.open_loop_unit());  // the poles at each gain: the Hessenberg reduction once
  const auto stable = [&](double k) { return path.spectral_radius(k, polarity) < 1.0; };
  const double k_max = control::kMaxGainNsPerM;
  const int n = 120;  // log scan 1 .. k_max N s/m
  const auto scan_gain = [&](int i) { return std::pow(k_max, static_cast<double>(i) / n); };
  int first = 0;
  if (crossing_gain_ns_per_m && *crossing_gain_ns_per_m > 1.0) {
    // Every scan step below the first crossing is stable (the poles move continuously with K and reach the
    // unit circle only where L meets -1); the step the scan would start from is checked, or it starts at 1.
    const double steps = std::log(kCrossingShare * *crossing_gain_ns_per_m) / std::log(k_max) * n;
    const int i0 = std::min(n, static_cast<int>(std::floor(steps)));
    if (i0 > 0 && stable(scan_gain(i0))) first = i0 + 1;
  }
  double lo = first > 0 ? scan_gain(first - 1) : 0.0, hi = 0.0;
  for (int i = first; i <= n; ++i) {
    const double k = scan_gain(i);
    if (!stable(k)) {
      hi = k;
      break;
    }
    lo = k;
  }
  if (hi == 0.0) return std::nullopt;
  while (hi - lo > 1e-6 * hi) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Margins margins(const LoopModel& m, double gain, int polarity, std::optional<double> max_gain) {
  Margins r;
  if (max_gain) r.gain_margin_db = gain_margin_db(*max_gain, gain);
  // Log grid over (0.1 Hz, Nyquist), crossings refined by bisection.
  const LogGrid grid{0.1, 0.499 * m.loop_rate_hz(), 6000};
  const int n = grid.intervals;
  const auto sweep = m.plant_sweep(grid);  // the plant on the grid, shared by the loops on this plant
  auto f_at = [&](int i) { return grid.at(i); };
  auto loop = [&](double f) { return m.loop_discrete(f, gain, polarity); };
  auto loop_at = [&](int i) {
    const double f = f_at(i);
    return m.loop_discrete((*sweep)[static_cast<std::size_t>(i)], m.chain_filters_digital(f), gain, polarity);
  };
  // L at gain K meets -1 at gain K / |L| where it crosses the negative real axis; at the sweep's ends (0.1 Hz,
  // Nyquist) L on the negative side counts as one, for a crossing beyond them.
  const auto note_crossing = [&](Complex l) {
    if (gain <= 0.0 || !(l.real() < 0.0)) return;
    const double k = gain / std::abs(l);
    if (!r.crossing_gain_ns_per_m || k < *r.crossing_gain_ns_per_m) r.crossing_gain_ns_per_m = k;
  };
  note_crossing(loop(0.5 * m.loop_rate_hz()));
  Complex prev = loop_at(0);
  note_crossing(prev);
  double best_phase_cross_gap = std::numeric_limits<double>::infinity();
  for (int i = 1; i <= n; ++i) {
    const double f0 = f_at(i - 1), f1 = f_at(i);
    const Complex cur = loop_at(i);
    if ((std::abs(prev) - 1.0) * (std::abs(cur) - 1.0) < 0.0) {
      double a = f0, b = f1;
      const bool rising = std::abs(prev) < 1.0;
      for (int it = 0; it < 60; ++it) {
        const double c = 0.5 * (a + b);
        ((std::abs(loop(c)) < 1.0) == rising ? a : b) = c;
      }
      const double fc = 0.5 * (a + b);
      const double arg_deg = std::arg(loop(fc)) * 180.0 / M_PI;
      // Angular distance of L from -1 at the crossover, and the extra lag (a pure delay turns L
      // clockwise) that would bring it there.
      const double pm = 180.0 - std::abs(arg_deg);
      const double lag_deg = std::fmod(arg_deg + 180.0 + 360.0, 360.0);
      if (!r.phase_margin_deg || pm < *r.phase_margin_deg) r.phase_margin_deg = pm, r.gain_crossover_hz = fc;
      const double dm = lag_deg * M_PI / 180.0 / (kTwoPi * fc) * 1e3;
      if (!r.delay_margin_ms || dm < *r.delay_margin_ms) r.delay_margin_ms = dm;
    }
    if (prev.imag() * cur.imag() < 0.0 && cur.real() < 0.0) {
      double a = f0, b = f1;  // refine the crossing of the negative real axis
      const bool from_above = prev.imag() > 0.0;
      for (int it = 0; it < 60; ++it) {
        const double c = 0.5 * (a + b);
        ((loop(c).imag() > 0.0) == from_above ? a : b) = c;
      }
      const double fp = 0.5 * (a + b);
      const Complex at_crossing = loop(fp);
      note_crossing(at_crossing);
      const double gap = std::abs(std::log(std::abs(at_crossing)));
      if (gap < best_phase_cross_gap) best_phase_cross_gap = gap, r.phase_crossover_hz = fp;
    }
    prev = cur;
  }
  return r;
}

std::vector<FrfResult> improvements(const LoopModel& m, double gain, int polarity, bool discrete) {
  const auto& cfg = m.config();
  const std::vector<double> grid = linear_grid(cfg.analysis.band_min_hz, cfg.analysis.band_max_hz, 0.02);
  std::vector<PlantResponse> pr;
  std::vector<Complex> filt;
  if (discrete)
    for (double f : grid) pr.push_back(m.plant_response(f)), filt.push_back(m.chain_filters_digital(f));
  std::vector<FrfResult> out;
  for (const auto& f : cfg.robot.frfs) {
    FrfResult r;
    r.name = f.name;
    r.response = m.plant().index_of(f.response_location);
    r.excitation = m.plant().index_of(f.excitation_location);
    auto open = [&](double fr) {
      return discrete ? std::abs(m.open_discrete(m.plant_response(fr), r.response, r.excitation))
                      : std::abs(m.open_continuous(r.response, r.excitation, fr));
    };
    auto closed = [&](double fr) {
      return discrete ? std::abs(m.closed_discrete(m.plant_response(fr), m.chain_filters_digital(fr), r.response,
                                                   r.excitation, gain, polarity))
                      : std::abs(m.closed_continuous(r.response, r.excitation, fr, gain, polarity));
    };
    std::vector<double> vo, vc;
    for (std::size_t i = 0; i < grid.size(); ++i) {
      if (discrete) {
        vo.push_back(std::abs(m.open_discrete(pr[i], r.response, r.excitation)));
        vc.push_back(std::abs(m.closed_discrete(pr[i], filt[i], r.response, r.excitation, gain, polarity)));
      } else {
        vo.push_back(open(grid[i]));
        vc.push_back(closed(grid[i]));
      }
    }
    const Peak po = find_peak(grid, vo, open), pc = find_peak(grid, vc, closed);
    r.open_peak_m_per_n = po.magnitude;
    r.open_peak_freq_hz = po.freq_hz;
    r.closed_peak_m_per_n = pc.magnitude;
    r.peak_freq_hz = pc.freq_hz;
    r.improvement_pct = (po.magnitude / pc.magnitude - 1.0) * 100.0;
    out.push_back(r);
  }
  return out;
}

std::vector<SweepPoint> gain_sweep(const LoopModel& m, int polarity, const std::vector<double>& gains) {
  const auto& cfg = m.config();
  const std::vector<double> grid = linear_grid(cfg.analysis.band_min_hz, cfg.analysis.band_max_hz, 0.05);
  std::vector<PlantResponse> pr;
  std::vector<Complex> filt;
  for (double f : grid) pr.push_back(m.plant_response(f)), filt.push_back(m.chain_filters_digital(f));
  std::vector<SweepPoint> out;
  const double fs = m.loop_rate_hz();
  for (double k : gains) {
    SweepPoint p;
    p.gain_ns_per_m = k;
    const Eigen::VectorXcd poles = m.closed_loop_poles(k, polarity);
    p.spectral_radius = poles.cwiseAbs().maxCoeff();
    p.least_damping_ratio = std::numeric_limits<double>::infinity();
    for (const Complex& z : poles) {
      if (std::abs(z) < 1e-9) continue;  // pure delays
      const Complex s = std::log(z) * fs;
      const double wn = std::abs(s), hz = wn / kTwoPi;
      if (hz < 0.5 || hz > 0.25 * fs || s.imag() <= 0.0) continue;
      const double zeta = -s.real() / wn;
      if (zeta < p.least_damping_ratio) p.least_damping_ratio = zeta, p.least_damped_hz = hz;
    }
    for (const auto& f : cfg.robot.frfs) {
      const std::size_t g = m.plant().index_of(f.response_location), h = m.plant().index_of(f.excitation_location);
      double open = 0.0, closed = 0.0;
      for (std::size_t i = 0; i < grid.size(); ++i) {
        open = std::max(open, std::abs(m.open_discrete(pr[i], g, h)));
        closed = std::max(closed, std::abs(m.closed_discrete(pr[i], filt[i], g, h, k, polarity)));
      }
      p.improvement_pct.push_back((open / closed - 1.0) * 100.0);
    }
    out.push_back(std::move(p));
  }
  return out;
}

AnalysisResult analyse(const LoopModel& m) {
  return analyse(m, m.config().controller.gain_ns_per_m, m.config().controller.polarity);
}

std::vector<ModePhase> mode_phases(const LoopModel& m, double gain, int polarity) {
  std::vector<ModePhase> out;
  const sim::FrfPath* loop_path = m.plant().path(m.sensor_location(), m.actuator_location());
  for (const auto& mode : loop_path->modes) {
    const double f = mode.wn_rad_per_s / kTwoPi;
    const Complex c = -m.feedback_continuous(f, gain, polarity) / Complex(0.0, kTwoPi * f);  // -F / v
    out.push_back({f, std::arg(c) * 180.0 / M_PI, c.real() > 0.0});
  }
  return out;
}

AnalysisResult analyse(const LoopModel& m, double gain, int polarity) {
  AnalysisResult r;
  r.gain_ns_per_m = gain;
  r.polarity = polarity;
  r.spectral_radius = m.spectral_radius(gain, polarity);
  r.stable = r.spectral_radius < 1.0;
  r.nyquist_encirclements = m.nyquist_encirclements(gain, polarity);
  if ((r.nyquist_encirclements == 0) != r.stable) {
    std::ostringstream os;
    os << "Nyquist count (" << r.nyquist_encirclements << ") and closed-loop poles (spectral radius "
       << r.spectral_radius << ") disagree: the pole test is taken";
    r.notes.push_back(os.str());
  }
  const double hi = std::max(1e4, 10.0 * m.loop_rate_hz());
  // From just above 0 Hz: the ideal integrator block alone is singular at s = 0 (its product is not).
  const double t = turns([&](double f) { return 1.0 + m.loop_continuous(f, gain, polarity); }, 1e-6, hi);
  r.stable_continuous = std::lround(2.0 * t) == 0;
  r.margins = margins(m, gain, polarity, std::nullopt);
  r.max_stable_gain_ns_per_m = max_stable_gain(m, polarity, r.margins.crossing_gain_ns_per_m);
  if (r.max_stable_gain_ns_per_m) r.margins.gain_margin_db = gain_margin_db(*r.max_stable_gain_ns_per_m, gain);

  r.modes = mode_phases(m, gain, polarity);
  const sim::FrfPath* loop_path = m.plant().path(m.sensor_location(), m.actuator_location());
  double dominant = 0.0, dominant_mag = -1.0;
  for (const auto& mode : r.modes) {
    const double mag = std::abs(loop_path->receptance(mode.freq_hz));
    if (mag > dominant_mag) dominant_mag = mag, dominant = mode.freq_hz;
  }
  const Complex c_plus = -m.feedback_continuous(dominant, gain, 1) / Complex(0.0, kTwoPi * dominant);
  r.recommended_polarity = c_plus.real() > 0.0 ? 1 : -1;
  {
    std::ostringstream os;
    os.precision(3);
    os << "at the dominant mode " << dominant << " Hz the feedback force with polarity +1 is at "
       << std::arg(c_plus) * 180.0 / M_PI
       << " deg from -velocity: " << (r.recommended_polarity == 1 ? "inside" : "outside")
       << " the damping window (-90, 90) deg";
    r.polarity_reason = os.str();
  }
  if (r.recommended_polarity != polarity)
    r.notes.push_back("controller.polarity = " + std::to_string(polarity) + " does not damp the dominant mode; " +
                      "the analysis recommends " + std::to_string(r.recommended_polarity));
  r.frfs_continuous = improvements(m, gain, polarity, false);
  r.frfs_discrete = improvements(m, gain, polarity, true);
  if (r.stable) {
    const QuietCommand q = quiet_command(m, gain, polarity);
    r.quiet_command_rms_v = q.rms_v, r.quiet_command_peak_hz = q.peak_density_hz;
    const double floor_v = m.config().supervision.instability_floor_v;
    if (floor_v > 0.0 && 3.0 * q.rms_v > floor_v) {
      std::ostringstream os;
      os.precision(3);
      os << "the command on a quiet cell is " << q.rms_v << " V RMS (most of it near " << q.peak_density_hz
         << " Hz), above a third of supervision.instability_floor_v = " << floor_v
         << " V: its swells can trip the instability detector on a stable loop; retune, or raise the floor to at least "
         << 3.0 * q.rms_v << " V";
      r.notes.push_back(os.str());
    }
  }
  for (const auto& n : m.plant().notes) r.notes.push_back(n);
  return r;
}

}  // namespace robodamp::analysis
