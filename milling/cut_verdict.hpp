// What the damper does for a cut, in the machinist's terms (docs/tuning.md, "Verdicts about the cut"): for a
// cell configuration and its milling job, the limiting depth of the open loop, of the cell's own controller at
// its fixed K, and, when the configuration has one, of its speed schedule (each speed with its band's
// controller and K), all by the accurate method (SDM open loop, the sampled loop's SDM damped) at the same
// speeds (the ones the sampled loop runs) over the job's lobes range and at the job's spindle speed. Which is
// better or worse than no damper, where, and by how much. Off the real-time path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"

namespace robodamp::milling {

struct CutCurve {
  double min_mm{0.0}, min_rpm{0.0};
  double mean_ratio{0.0};   // x the open loop, over the speeds
  double worse_share{0.0};  // of the speeds below the open loop by more than the tolerance
  double worst_ratio{0.0}, worst_rpm{0.0};
  double better_share{0.0};  // above the open loop by more than the tolerance
  double at_job_mm{0.0};     // at the job's speed
  std::vector<double> mm;    // per speed
};

struct CutVerdict {
  std::string job, method;
  double tolerance{0.005};            // what "worse" and "better" mean, relative to the open loop
  std::vector<double> rpm;            // the speeds (as the sampled loop runs them)
  double job_rpm{0.0};                // the job's spindle speed as the sampled loop runs it (0: beyond its range)
  CutCurve open, fixed;               // the open loop; the configuration's controller at controller.gain_ns_per_m
  std::optional<CutCurve> scheduled;  // controller.speed_schedule
  double fixed_gain_ns_per_m{0.0};
  std::size_t bands{0};
};

// speeds: over the job's lobes range (0: its time_domain.sdm_points). Throws config::ConfigError when the job
// has no damping location.
[[nodiscard]] CutVerdict cut_verdict(const config::Config& cell, const config::MillingConfig& job, int speeds = 0);

// The verdict's lines: the table, then "VERDICT (the cut): ..." saying what the damper does at the job's speed
// and over the range, with the tolerance.
[[nodiscard]] std::string cut_verdict_text(const CutVerdict& v);
// The one-line verdict alone.
[[nodiscard]] std::string cut_verdict_line(const CutVerdict& v);

}  // namespace robodamp::milling
