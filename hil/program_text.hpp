// The robot program's register changes as a person types them for the plant emulator (`robodamp plant`):
// a mounting change "T:horizontal|vertical", a step "T:VALUE" and a ramp "T0:T1:VALUE" of the spindle speed or
// the cut's depth, plant times in s. (The pose's waypoints: hil/pose_trajectory.hpp, parse_waypoint.)
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "hil/cutting_load.hpp"
#include "hil/plant_emulator.hpp"

namespace robodamp::hil {

// "T:horizontal" or "T:vertical", 0 <= T <= 1e7 s. False with the reason in `error`.
[[nodiscard]] bool parse_mounting(const std::string& item, std::pair<double, config::Mounting>& out,
                                  std::string& error);

// A step "T:VALUE" or, with `ramp`, "T0:T1:VALUE" (from the value at T0 to VALUE at T1, T0 <= T1) of `option`,
// VALUE within `value` (its unit "rpm" or "mm"); a step has t1_s = t0_s. False with the reason in `error`: the
// form expected and every field's allowed range.
[[nodiscard]] bool parse_change(const std::string& option, const std::string& item, const config::Range& value,
                                bool ramp, SpindleChange& out, std::string& error);

// The robot program as typed on `robodamp plant`'s command line, each repeatable option's items as given.
struct ProgramText {
  std::vector<std::string> mounting;       // "T:horizontal|vertical"
  std::vector<std::string> spindle;        // "T:RPM"
  std::vector<std::string> spindle_ramps;  // "T0:T1:RPM"
  std::vector<std::string> depth;          // "T:MM"
  std::vector<std::string> depth_ramps;    // "T0:T1:MM"
  std::vector<std::string> pose_at;        // "T:Q1,Q2,..." waypoints
};

// Every item parsed into the emulator's schedules, ramps, depth changes and pose trajectory, in that order.
// False with the first refusal in `error`, in the command line's words.
[[nodiscard]] bool apply_program(const ProgramText& text, EmulatorOptions& eo, std::string& error);

}  // namespace robodamp::hil
