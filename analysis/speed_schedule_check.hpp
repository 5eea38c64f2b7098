// A speed schedule's controllers checked as loops (controller.speed_schedule, docs/tuning.md): every distinct
// controller and K a band runs, its stability, margins and the feedback's phase at each mode, with the weak
// points said as warnings (a margin below what robodamp schedule keeps, a mode's feedback within 10 deg of the
// damping window's edge, no gain crossover). Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "analysis/loop_model.hpp"
#include "config/config.hpp"

namespace robodamp::analysis {

struct ScheduledLoop {
  std::size_t controller{0};  // 0: the configuration's own, i: speed_schedule.controllers[i - 1]
  double gain_ns_per_m{0.0};
  std::size_t bands{0};  // how many bands run it
  double rpm_from{0.0};  // the first band's start
  bool stable{false};
  std::optional<double> k_max_ns_per_m;
  Margins margins;
  std::vector<ModePhase> modes;
  std::vector<std::string> warnings;
  std::vector<std::string> notes;  // facts, not weaknesses (no gain crossover)
};

// Bands at K 0 are the open loop and are left out. gm_min_db, pm_min_deg: what a warning is below.
[[nodiscard]] std::vector<ScheduledLoop> check_speed_schedule(const config::Config& cell, double gm_min_db = 6.0,
                                                              double pm_min_deg = 45.0);

}  // namespace robodamp::analysis
