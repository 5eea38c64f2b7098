// What robodamp tune promises, verified before anything is written (docs/tuning.md, "Verified promises"):
// the damped lobes of the job by the accurate method (the sampled loop's semi-discretization,
// milling/accurate_stability.hpp) over the job's speed range, the depth at the job's speed, and the damped
// time-domain cut with the real Controller (the simulated plant at the loop rate) at the job's speed and at
// the accurate lobes' minimum. Off the real-time path.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"

namespace robodamp::tune {

struct Verification {
  std::string method;        // of the damped limits: "sampled-loop SDM"
  double min_depth_mm{0.0};  // the damped lobes' minimum over the job's speed range
  double min_rpm{0.0};
  double depth_at_speed_mm{0.0};        // at the job's spindle speed
  double speed_rpm{0.0};                // the job's speed as analysed (a whole number of loop periods per tooth)
  double open_min_depth_mm{0.0};        // the open loop's SDM minimum over the same speeds
  double time_domain_at_speed_mm{0.0};  // the time-domain cut's critical depth at the job's speed
  double time_domain_at_min_mm{0.0};    // and at the damped lobes' minimum
  std::vector<std::pair<double, double>> damped_curve_mm;  // rpm, mm
  // The time domain within `tolerance` of both promises (its revolutions resolve the limit to about 1 %).
  [[nodiscard]] bool time_domain_agrees(double tolerance = 0.05) const;
};

// The damped cut's critical depth in time at `rpm` (the time-domain cut with the real Controller running
// cfg's controller on cfg's plant, at least 300 revolutions), mm; guess_mm starts the bracket.
[[nodiscard]] double time_domain_critical_mm(const config::Config& cfg, const config::MillingConfig& job, double rpm,
                                             double guess_mm);

// Throws config::ConfigError for a job or configuration that cannot be analysed.
[[nodiscard]] Verification verify(const config::Config& cfg, const config::MillingConfig& job);

}  // namespace robodamp::tune
