// How far a tuned loop stays good as the robot's modes move (a pose change, a tool change, wear): every modal
// frequency scaled down and up together (tune::with_shifted_modes) until the loop is unstable or a mode it damps
// as configured is fed back outside the damping window (it stops damping that mode; modes it does not damp as
// configured are the analysis' warnings, not this). What the tune was asked to hold (commission's
// +-shift from the fits' spread) says nothing about how much more it holds; this measures it. Off the RT path.
#pragma once

#include <string>

#include "config/config.hpp"

namespace robodamp::tune {

struct ShiftLimit {
  double pct{0.0};          // the largest shift (in steps of step_pct) with the loop stable and its damped modes damped
  bool reached_max{false};  // good up to max_pct
  std::string reason;       // what failed one step further ("unstable", "the 21.0 Hz mode at 94 deg: not damped")
};

struct Robustness {
  ShiftLimit down, up;
  [[nodiscard]] double pct() const { return down.pct < up.pct ? down.pct : up.pct; }
};

// cfg: the loop as configured (its controller.gain_ns_per_m and polarity).
[[nodiscard]] Robustness robustness(const config::Config& cfg, double max_pct = 20.0, double step_pct = 0.5);

// A robustness under this (either way) is a weak point the commissioning report and log warn about: a robot's
// modes move by more than that from one pose to the next (docs/pose_dynamics.md: 10 to 21 Hz along one path).
inline constexpr double kRobustShiftWarnPct = 5.0;

}  // namespace robodamp::tune
