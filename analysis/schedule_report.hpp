// What `robodamp analyze` reports of a cell's schedules (docs/commands.md): the harmonic notches across the
// spindle's speed range (--spindle-sweep), the pose schedule's regions, and the speed schedule's controllers
// as loops; JSON and text. Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "config/config.hpp"

namespace robodamp::analysis {

struct TextReport {
  nlohmann::json json;
  std::string text;
};

// The notches' phase at each mode over spindle.rpm's range and the speeds refused there.
[[nodiscard]] TextReport notch_speed_map_report(const config::Config& cfg);

// Each pose region's set analysed over its grid (analysis/pose_schedule.hpp): throws config::ConfigError for a
// region with no stable set.
[[nodiscard]] TextReport pose_schedule_report(const config::Config& cfg);

// controller.speed_schedule: each controller and K its bands run, checked as a loop, with its weak points, into
// report["speed_schedule"]; the text's lines (empty without a speed schedule).
[[nodiscard]] std::string speed_schedule_section(const config::Config& cfg, nlohmann::json& report);

}  // namespace robodamp::analysis
