// The file `robodamp schedule --out` writes: the cell's configuration with its controller.speed_schedule, behind
// a header that says where it comes from, the command that writes it again and the schedule's verdict
// (docs/tuning.md). Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include "config/config.hpp"
#include "tune/speed_schedule.hpp"

namespace robodamp::tune {

// What `robodamp schedule` was asked (its options as given).
struct ScheduleCommand {
  std::string config_path, job_path;
  std::vector<std::string> controllers;  // more controllers' files to choose from
  std::string out_path;
  ScheduleSettings settings;
};

// The command that writes the file again (the options that differ from their defaults).
[[nodiscard]] std::string schedule_command_line(const ScheduleCommand& c);

// The cell's text with the schedule (a header this command wrote before replaced, not stacked), its relative
// paths rebased to c.out_path, checked by the configuration's rules (throws config::ConfigError) before it is
// returned; comments_kept false when the cell's text could not be edited in place.
[[nodiscard]] std::string scheduled_file_text(const ScheduleCommand& c, config::Config cell, const SpeedSchedule& s,
                                              bool& comments_kept);

}  // namespace robodamp::tune
