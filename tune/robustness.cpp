#include "tune/robustness.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include "analysis/loop_model.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp::tune {

config::Config with_shifted_modes(const config::Config& base, double factor) {
  config::Config cfg = base;
  // The controller stays the nominal's: its compensator pre-warped and scaled at the nominal match frequency.
  cfg.controller.match_freq_hz = unity_gain_hz(base);
  for (auto& frf : cfg.robot.frfs)
    for (auto& mode : frf.modes) {
      mode.natural_freq_hz *= factor;
      mode.residue_re_m_per_n /= factor;
      mode.residue_im_m_per_n /= factor;
      mode.stiffness_n_per_m *= factor * factor;
    }
  return cfg;
}

namespace {

std::vector<analysis::ModePhase> phases_at(const config::Config& cfg, double factor, bool& stable) {
  const config::Config shifted = with_shifted_modes(cfg, factor);
  const analysis::LoopModel m(shifted);
  stable = m.stable(shifted.controller.gain_ns_per_m, shifted.controller.polarity);
  return analysis::mode_phases(m, shifted.controller.gain_ns_per_m, shifted.controller.polarity);
}

// Empty when the loop at this shift is stable and every mode it damps as configured is still damped (the modes
// are scaled together, so they keep their order); else what is wrong.
std::string fault_at(const config::Config& cfg, double factor, const std::vector<analysis::ModePhase>& nominal) {
  bool stable = false;
  const std::vector<analysis::ModePhase> phases = phases_at(cfg, factor, stable);
  if (!stable) return "the loop unstable";
  for (std::size_t i = 0; i < phases.size() && i < nominal.size(); ++i)
    if (const auto& mode = phases[i];
        std::abs(nominal[i].feedback_phase_deg) < 90.0 && std::abs(mode.feedback_phase_deg) >= 90.0) {
      char b[160];
      std::snprintf(b, sizeof b, "the %.1f Hz mode fed back at %.0f deg: not damped", mode.freq_hz,
                    mode.feedback_phase_deg);
      return b;
    }
  return {};
}

ShiftLimit limit(const config::Config& cfg, const std::vector<analysis::ModePhase>& nominal, double sign,
                 double max_pct, double step_pct) {
  ShiftLimit out;
  const int steps = static_cast<int>(std::floor(max_pct / step_pct + 1e-9));
  for (int i = 1; i <= steps; ++i) {
    const double pct = i * step_pct;
    if (std::string why = fault_at(cfg, 1.0 + sign * pct / 100.0, nominal); !why.empty()) {
      char b[64];
      std::snprintf(b, sizeof b, "at %+.1f %%: ", sign * pct);
      out.reason = b + why;
      return out;
    }
    out.pct = pct;
  }
  out.reached_max = true;
  return out;
}

}  // namespace

Robustness robustness(const config::Config& cfg, double max_pct, double step_pct) {
  Robustness r;
  bool stable = false;
  const std::vector<analysis::ModePhase> nominal = phases_at(cfg, 1.0, stable);
  if (!stable) {
    r.down.reason = r.up.reason = "as configured: the loop unstable";
    return r;
  }
  r.down = limit(cfg, nominal, -1.0, max_pct, step_pct);
  r.up = limit(cfg, nominal, 1.0, max_pct, step_pct);
  return r;
}

}  // namespace robodamp::tune
