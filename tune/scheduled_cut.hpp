// A speed schedule in time (docs/tuning.md, "Checked in time"): the scheduled cell's parameter sets under the
// real supervisor and controller (rt::Supervisor, control::Controller: the same code the loop runs), the
// simulated robot and actuator (sim::Plant), and the time-domain cut, with the spindle moving from one speed
// to the next while the damper runs. At each speed, out of the cut as a machinist changes speed, the
// supervisor follows the schedule (K ramps; another band's controller is handed over: the running chain fades
// out at once, the incoming one warms up, then fades in), then a cut runs at the depth asked. What each switch
// asked of the actuator, what each cut did (stable or chatter, by the chatter detector) and what the damper
// ran there. Off the real-time path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/chatter.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::tune {

struct ScheduledCutStep {
  double rpm{0.0};  // asked for
  double depth_mm{0.0};
};

struct ScheduledCutSegment {
  double rpm{0.0};  // as cut (a whole number of loop periods per tooth period)
  double depth_mm{0.0};
  std::size_t set{0};         // the supervisor's set when the cut ended
  double gain_ns_per_m{0.0};  // K asked for there
  milling::ChatterVerdict verdict;
  double switch_s{0.0};                   // from the speed change to K settled on the band's set
  double switch_peak_force_n{0.0};        // the controller's force command through the switch
  std::uint64_t switch_limited_ticks{0};  // ticks at a controller limit (force, voltage, slew) through the switch
  double peak_force_command_n{0.0};       // the controller's force command through the cut (its entry included)
  std::uint64_t limited_ticks{0};         // ticks at a controller limit through the cut
  std::string state, trip;                // the supervisor's at the end
  double lowest_derate{1.0};              // the supervisor's derating through the cut (1: none)
  double derated_s{0.0};                  // time through the cut with the command derated
  double trip_s{-1.0};                    // from the cut's start to a trip (-1: none)
};

struct ScheduledCut {
  std::vector<ScheduledCutSegment> segments;
  double force_limit_n{0.0};  // the actuator's (actuator.force_limit_n)
  std::uint64_t handovers{0}, handovers_refused{0};
  rt::SupervisorCounters counters;  // the supervisor's at the end
  [[nodiscard]] bool all_stable() const;
  [[nodiscard]] bool switches_within_limits() const;  // no limit acted through a switch, the force below the limit
};

// cell: a configuration with controller.speed_schedule; the cuts run in the order given, the damper armed
// before the first and running throughout. revolutions: per cut after the switch has settled.
[[nodiscard]] ScheduledCut scheduled_cut(const config::Config& cell, const config::MillingConfig& job,
                                         const std::vector<ScheduledCutStep>& steps, int revolutions = 60);

// The same with any cell (a speed schedule or not) and a robot that may differ from it: plant (null: the cell's
// own) is what the structure, the actuator and its limits really are; the supervisor and controller run the
// cell's configuration and analysis. A trip ends the steps (the segments so far are returned).
struct SupervisedCutOptions {
  const config::Config* plant{nullptr};
  int revolutions{60};
};
[[nodiscard]] ScheduledCut supervised_cut(const config::Config& cell, const config::MillingConfig& job,
                                          const std::vector<ScheduledCutStep>& steps, const SupervisedCutOptions& o);

}  // namespace robodamp::tune
