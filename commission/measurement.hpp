// The commissioning measurement (docs/identification.md, "Commissioning"): the configured cell runs with
// control off (K = 0) and the amplifier enabled, through the same loop and drivers as `robodamp run`: a
// periodic chirp on the actuator inside the force and voltage limits, then hammer impacts at every location.
// The loop records every tick; the plant side writes the impact FRFs (in process for the simulated plant;
// `robodamp plant --measure-out DIR` with hardware). `robodamp measure` and `robodamp commission` run it.
#pragma once

#include <string>

#include "identify/commissioning.hpp"

namespace robodamp::commission {

struct MeasureOptions {
  std::string clock;  // "", "wall" or "virtual" (default: the configuration's, virtual on the simulated plant)
  // The robot's joint angles, deg, one per joint of the configuration's pose_schedule.model (empty: not
  // stated). The simulated plant is the robot model at this pose; on hardware the robot stands there (the
  // user moved it). Written to measurement.json for `pose fit --measurements` and the pose-indexed model.
  std::vector<double> pose_deg;
  std::string pose_name;
};

enum class MeasureStatus { kOk, kConfigError, kFailed, kTripped, kIncomplete, kWriteError };

struct MeasureOutcome {
  MeasureStatus status{MeasureStatus::kOk};
  std::string message;  // why, when not ok
  identify::MeasurementManifest manifest;
  std::string final_state, trip;
  double chirp_active_share{0.0};
  unsigned long long saturated_ticks{0}, recorded_frames{0};
  double peak_command_v{0.0};
  int impact_records{0}, impact_records_planned{0};
  std::size_t frf_files{0};
};

// Runs the measurement into out_dir (created). Progress lines go to spdlog. Throws config::ConfigError for
// a configuration that does not validate.
[[nodiscard]] MeasureOutcome measure(const std::string& config_path, const std::string& out_dir,
                                     const MeasureOptions& o = {});

// The exit code the commands use: 0 ok, 2 configuration, 4 tripped, 5 incomplete, 1 otherwise.
[[nodiscard]] int exit_code(MeasureStatus s);

}  // namespace robodamp::commission
