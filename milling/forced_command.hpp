// The damper's force the cut's own forced vibration asks for (docs/milling.md, "Where the actuator holds"):
// the cutting force's harmonics at the tooth-passing frequency (milling/cutting.hpp: force_spectrum, exact
// over the helix's slices) through the closed loop's command per force at each controller part's location
// (analysis::LoopModel::command_per_force, the discrete loop that runs), summed over one tooth period. Every
// damped limit of the linear stability analysis assumes an actuator without a force limit; a cut whose forced
// vibration alone drives the coil force to actuator.force_limit_n (or the amplifier's voltage range) loses the
// damping the limit counted on and chatters below it (measured in time, tests/test_speed_schedule.cpp). The
// depth where the actuator holds caps what a damped controller can promise. Without chatter, at steady state;
// harmonic notches are not in the loop here (they would lower the command: this errs on the safe side). Off
// the real-time path.
#pragma once

#include <vector>

#include "config/milling_config.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

class ForcedCommand {
 public:
  // damped: a structure with its controller parts closed (their gain and polarity); at this speed.
  ForcedCommand(const Structure& damped, const config::MillingConfig& job, double rpm);
  // The largest coil force over a tooth period at this depth, N (the largest over the controller parts).
  [[nodiscard]] double peak_force_n(double axial_mm) const;
  // What the actuator can give: min(actuator.force_limit_n, amplifier.voltage_limit_v x constant_n_per_v).
  [[nodiscard]] double limit_n() const { return limit_n_; }
  // The depth up to max_mm where the forced coil force first reaches the limit, scanning up (max_mm when it holds
  // all the way; to 1/64 of max_mm, then bisected).
  [[nodiscard]] double holding_depth_mm(double max_mm) const;

 private:
  struct Part {
    std::size_t direction{1};
    std::vector<Complex> newton_per_newton;  // coil force per cutting force at harmonic k (k = 0 unused)
  };
  const config::MillingConfig& job_;
  double rpm_;
  double limit_n_{0.0};
  std::vector<Part> parts_;
};

// Each speed's damped limit capped where the actuator holds: min(limit_mm[i], the holding depth at rpm[i]), on
// `threads` threads (0: one per core). Open-loop structures (no controller part) are returned as they are.
[[nodiscard]] std::vector<double> holding_limits_mm(const Structure& damped, const config::MillingConfig& job,
                                                    const std::vector<double>& rpm, const std::vector<double>& limit_mm,
                                                    std::size_t threads = 0);

}  // namespace robodamp::milling
