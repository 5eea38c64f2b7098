// How much the closed loop lowers the receptance's peak near each robot mode: the first configured FRF
// (the TCP's on the presets), the discrete loop, the largest |H| within +-10 % of each mode's frequency,
// open against closed. Negative: the loop makes that mode worse. Used by `tune`'s report and its
// --no-worse-mode constraint, and by the pose schedule's check of each region's worst mode.
#pragma once

#include <optional>
#include <vector>

#include "analysis/loop_model.hpp"

namespace robodamp::analysis {

struct ModeImprovement {
  double freq_hz{0.0};
  double open_peak_m_per_n{0.0}, closed_peak_m_per_n{0.0};
  double improvement_pct{0.0};  // open / closed - 1
};

// Empty when the configuration has no FRF or the loop is unstable at this gain and polarity.
[[nodiscard]] std::vector<ModeImprovement> mode_improvements(const LoopModel& m, double gain_ns_per_m, int polarity);

// The mode with the smallest improvement among those with min_hz <= frequency <= max_hz (inside: true) or
// outside that band (inside: false); nothing when no mode is there.
[[nodiscard]] std::optional<ModeImprovement> worst_mode(const std::vector<ModeImprovement>& modes, double min_hz,
                                                        double max_hz, bool inside = true);

// The worst mode inside a band and the worst outside it, folded over several loops (the poses of a region,
// the sets that can run at a pose).
struct BandWorst {
  std::optional<ModeImprovement> inside, outside;
  // Folds one loop's modes in; true when the worst inside the band is now one of them.
  bool add(const std::vector<ModeImprovement>& modes, double min_hz, double max_hz);
};

}  // namespace robodamp::analysis
