// What a speed schedule (tune/speed_schedule.hpp) does for the job, said in the machinist's terms: the depth
// at the job's speed, the minimum, the mean over the range, where the damper is worse than none and by how
// much, with the controller as configured beside it; the bands; the same as JSON; the lobes as a plot's data.
// Every depth is the accurate method's, which the text names. Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "tune/speed_schedule.hpp"

namespace robodamp::tune {

// The verdict lines: what the fixed gain does, what the schedule does, each criterion with its tolerance.
[[nodiscard]] std::string schedule_text(const SpeedSchedule& s, const std::string& cell, const std::string& job);
[[nodiscard]] nlohmann::json schedule_json(const SpeedSchedule& s);
// The written file's header lines (each starting "# "): the schedule's promises, as verified.
[[nodiscard]] std::string schedule_header(const SpeedSchedule& s);
// Gnuplot data and script for the lobes: open loop, the configured controller, the schedule (PNG at path).
[[nodiscard]] std::pair<std::string, std::string> schedule_plot(const SpeedSchedule& s, const std::string& title);

}  // namespace robodamp::tune
