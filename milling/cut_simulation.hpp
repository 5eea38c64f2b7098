// Time-domain simulation of a milling cut with regenerative chatter (docs/milling.md, "Time domain").
// The structure (milling/tool_dynamics.hpp) is stepped exactly at h = tooth period / steps_per_tooth.
// The cutter has axial slices with helix lag (a ball end's slices on the sphere, as in the
// frequency-domain model), per-tooth radial runout, and the linear force model with edge coefficients
// (docs/physics.md §2-4) or its exponential form (material.force_model: exponential). The chip comes from the surface each slice's previous passes actually
// left at that angle: a surface memory per slice and angular position, so runout and the tool leaving
// the cut (h <= 0: no force, the surface is not renewed) come out right. Off the real-time path.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "config/milling_config.hpp"
#include "milling/cutting.hpp"
#include "milling/tool_dynamics.hpp"

namespace robodamp::milling {

struct CutSettings {
  double rpm{0.0};
  CutConditions cut;
  int axial_slices{20};
  int steps_per_tooth{40};
  int revolutions{60};
  int settle_revolutions{20};
  std::vector<double> runout_um;  // per tooth (empty: none)
  std::vector<double> pitch_deg;  // angle from each tooth to the next (empty: even pitch); on the step grid
};

// The steps per tooth period for a job: the configured value, or the fewest (at least 40) that give
// min_steps_per_mode_period steps per period of the highest mode.
[[nodiscard]] int steps_per_tooth(const config::TimeDomainConfig& td, double highest_mode_hz, double rpm, int teeth);

struct CutRecord {
  double rpm{0.0};
  double step_s{0.0};
  int teeth{0};
  int steps_per_tooth{0};
  std::size_t settle_steps{0};  // statistics start here
  // Per step, cutter frame (x = feed, y = wall normal): tool displacement at the step's start, m, and the
  // cutting force on the tool held over the step, N.
  std::vector<double> x_m, y_m, fx_n, fy_n;
  double peak_force_n{0.0};  // after settling
  // With the damper (milling/damped_dynamics.hpp), after settling: the actuator's peak transmitted force
  // and the time at a controller or actuator limit; NaN and 0 without.
  double peak_actuator_force_n{std::numeric_limits<double>::quiet_NaN()};
  double actuator_saturated_s{0.0};
  double sle_um{0.0};                   // wall error after settling, mean over the engaged slices (+ = undercut)
  std::vector<double> wall_um;          // per slice (tip first), NaN where the slice does not reach the wall
  std::vector<double> wall_per_rev_um;  // the machined wall per revolution after settling (mean over slices)
  std::uint64_t engaged_samples{0};     // tooth-slice steps wholly inside the engagement after settling
  std::uint64_t out_of_cut_samples{0};  // of those, with no chip (h <= 0): the tool left the cut
  [[nodiscard]] double out_of_cut_share() const {
    return engaged_samples ? static_cast<double>(out_of_cut_samples) / static_cast<double>(engaged_samples) : 0.0;
  }
};

[[nodiscard]] CutRecord simulate_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                                     const config::MaterialConfig& material, const CutSettings& settings);
// The same with the structure given as dynamics stepping at the tooth period / settings.steps_per_tooth.
[[nodiscard]] CutRecord simulate_cut(CutDynamics& dynamics, const Cutter& cutter,
                                     const config::MaterialConfig& material, const CutSettings& settings);

}  // namespace robodamp::milling
