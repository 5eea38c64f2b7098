#include "analysis/notch_speed_map.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "units/units.hpp"

namespace robodamp::analysis {

namespace {

// Damping at each mode of the loop's own path: the feedback force against -velocity in (-90, 90) deg.
std::vector<bool> damps(const LoopModel& m, const std::vector<double>& modes_hz, double gain, int polarity) {
  std::vector<bool> out;
  for (double f : modes_hz)
    out.push_back((-m.feedback_continuous(f, gain, polarity) / Complex(0.0, kTwoPi * f)).real() > 0.0);
  return out;
}

}  // namespace

NotchSpeedMap notch_speed_map(const config::Config& cfg, int points) {
  if (!cfg.controller.harmonic_notch || points < 2) return {};
  return notch_speed_map(LoopModel(cfg), points);
}

NotchSpeedMap notch_speed_map(const LoopModel& plain, int points) {
  if (plain.spindle_rpm())
    throw std::invalid_argument("notch_speed_map: the plain loop, not one with the notches at a spindle speed");
  NotchSpeedMap map;
  const config::Config& cfg = plain.config();
  if (!cfg.controller.harmonic_notch || points < 2) return map;
  const double gain = cfg.controller.gain_ns_per_m;
  const int pol = cfg.controller.polarity;
  std::vector<double> modes_hz;
  if (const sim::FrfPath* path = plain.plant().path(plain.sensor_location(), plain.actuator_location()))
    for (const auto& mode : path->modes) modes_hz.push_back(mode.wn_rad_per_s / kTwoPi);
  const std::vector<bool> base = damps(plain, modes_hz, gain, pol);
  const double lo = std::max(1.0, cfg.controller.harmonic_notch->min_hz * 60.0 / cfg.spindle.teeth);
  const double hi = std::max(lo * 1.0001, cfg.spindle.rpm_max);
  for (int i = 0; i < points; ++i) {
    NotchSpeedPoint p;
    p.rpm = lo * std::pow(hi / lo, static_cast<double>(i) / (points - 1));
    p.tooth_hz = p.rpm * cfg.spindle.teeth / 60.0;
    const LoopModel m = plain.at_speed(p.rpm);
    p.notches = m.notch_count();
    p.spectral_radius = m.spectral_radius(gain, pol);
    p.stable = p.spectral_radius < 1.0;
    p.mode_hz = modes_hz;
    const std::vector<bool> now = damps(m, modes_hz, gain, pol);
    for (std::size_t k = 0; k < modes_hz.size(); ++k) {
      p.notch_phase_deg.push_back(std::arg(m.notch_response(modes_hz[k])) * 180.0 / M_PI);
      if (base[k] && !now[k] && p.reason.empty()) {
        char b[160];
        std::snprintf(b, sizeof b, "the notches push the %.2f Hz mode out of its damping window (%.1f deg)",
                      modes_hz[k], p.notch_phase_deg.back());
        p.reason = b;
      }
    }
    if (!p.stable)
      p.reason =
          "the loop is unstable at K with the notches here (spectral radius " + std::to_string(p.spectral_radius) + ")";
    p.refused = !p.reason.empty();
    map.points.push_back(std::move(p));
  }
  // Refused runs, widened to the accepted neighbours (the grid does not see between its points).
  const auto& pts = map.points;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].refused) continue;
    std::size_t j = i;
    while (j + 1 < pts.size() && pts[j + 1].refused) ++j;
    map.refused_rpm.emplace_back(i > 0 ? pts[i - 1].rpm : 0.0,
                                 j + 1 < pts.size() ? pts[j + 1].rpm : cfg.spindle.rpm_max);
    i = j;
  }
  return map;
}

void apply_refused_speeds(const NotchSpeedMap& map, control::ControllerParams& p) {
  std::vector<std::pair<double, double>> r = map.refused_rpm;
  while (r.size() > control::ControllerParams::kMaxRefusedSpeeds) {
    std::size_t best = 0;
    for (std::size_t i = 1; i + 1 < r.size(); ++i)
      if (r[i + 1].first - r[i].second < r[best + 1].first - r[best].second) best = i;
    r[best].second = r[best + 1].second;
    r.erase(r.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  }
  p.refused_rpm_count = r.size();
  for (std::size_t i = 0; i < r.size(); ++i) p.refused_rpm[i] = r[i];
}

}  // namespace robodamp::analysis
