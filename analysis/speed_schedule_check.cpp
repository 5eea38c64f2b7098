#include "analysis/speed_schedule_check.hpp"

#include <cmath>
#include <cstdio>
#include <map>

namespace robodamp::analysis {

namespace {

std::string fmt(const char* f, double a, double b = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

void warn(ScheduledLoop& l, double gm_min_db, double pm_min_deg) {
  if (!l.stable) l.warnings.push_back("the loop is UNSTABLE at this K");
  if (l.margins.gain_margin_db && *l.margins.gain_margin_db < gm_min_db)
    l.warnings.push_back(fmt("gain margin %.1f dB, below %.1f dB", *l.margins.gain_margin_db, gm_min_db));
  if (l.margins.phase_margin_deg && *l.margins.phase_margin_deg < pm_min_deg)
    l.warnings.push_back(fmt("phase margin %.1f deg, below %.1f deg", *l.margins.phase_margin_deg, pm_min_deg));
  if (!l.margins.gain_crossover_hz)
    l.notes.push_back(
        "no gain crossover: the loop gain stays below 1, so there is no phase margin to state (not 180 deg)");
  for (const ModePhase& m : l.modes)
    if (m.damps && std::abs(m.feedback_phase_deg) > 80.0)
      l.warnings.push_back(
          fmt("the %.2f Hz mode's feedback is at %.1f deg from -velocity, within 10 deg of the damping "
              "window's edge (90 deg): a small shift of the mode or the delay makes it stop damping",
              m.freq_hz, m.feedback_phase_deg));
}

}  // namespace

std::vector<ScheduledLoop> check_speed_schedule(const config::Config& cell, double gm_min_db, double pm_min_deg) {
  std::vector<ScheduledLoop> out;
  if (!cell.controller.speed_schedule) return out;
  std::map<std::pair<std::size_t, double>, std::size_t> seen;
  for (const auto& b : cell.controller.speed_schedule->bands) {
    if (b.gain_ns_per_m <= 0.0) continue;
    const std::pair<std::size_t, double> key{static_cast<std::size_t>(b.controller), b.gain_ns_per_m};
    if (const auto it = seen.find(key); it != seen.end()) {
      ++out[it->second].bands;
      continue;
    }
    seen[key] = out.size();
    ScheduledLoop l;
    l.controller = key.first;
    l.gain_ns_per_m = key.second;
    l.bands = 1;
    l.rpm_from = b.rpm_min;
    const config::Config c = key.first == 0 ? cell : config::speed_controller_config(cell, key.first);
    const LoopModel m(c);
    const int pol = c.controller.polarity;
    l.stable = m.stable(l.gain_ns_per_m, pol);
    l.k_max_ns_per_m = max_stable_gain(m, pol);
    l.margins = margins(m, l.gain_ns_per_m, pol, l.k_max_ns_per_m);
    l.modes = mode_phases(m, l.gain_ns_per_m, pol);
    warn(l, gm_min_db, pm_min_deg);
    out.push_back(std::move(l));
  }
  return out;
}

}  // namespace robodamp::analysis
