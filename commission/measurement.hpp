// The commissioning measurement (docs/identification.md, "Commissioning"): the configured cell runs with
// control off (K = 0) and the amplifier enabled, through the same loop and drivers as `robodamp run`: a
// periodic chirp on the actuator inside the force and voltage limits (its level ramped up over half its
// first period), then hammer impacts at every location. The loop records every tick; the plant side writes
// the impact FRFs (in process for the simulated plant; `robodamp plant --measure-out DIR` with hardware).
// `robodamp measure` and `robodamp commission` run it.
//
// On a real cell (no hammer robodamp can order) the actuator is the only shaker: impacts off, the chirp
// alone gives the actuator-location FRF (acceleration per volt, with coherence); with control on it is the
// verification's closed-loop chirp (commission/real_cell_check.hpp). Safety, watched on every frame:
// the chirp does not start unless the loop is active (amplifier ready, sensor fresh, robot state known)
// and the cell is at rest; a tick the supervisor limits during the chirp stops the run (the excitation
// saturates: the measurement would not be linear); SIGINT / SIGTERM abort it through the safe state.
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
  bool impacts{true};      // false: the actuator's chirp only (a real cell: the operator's hammer is not robodamp's)
  bool control_on{false};  // true: the configuration's controller runs through the chirp (the verification)
};

enum class MeasureStatus {
  kOk,
  kConfigError,
  kFailed,
  kTripped,
  kIncomplete,
  kWriteError,
  kNotReady,
  kSaturated,
  kAborted
};

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
  double rest_accel_rms_mps2{0.0};  // the last second before the chirp
};

// What a measurement with these options will do on this cell, for --dry-run and the log: what moves, the
// levels against the limits, the durations, what stops it. Throws config::ConfigError.
[[nodiscard]] std::string measurement_plan(const std::string& config_path, const MeasureOptions& o = {});
[[nodiscard]] std::string measurement_plan(const config::Config& cfg, const std::string& config_path,
                                           const MeasureOptions& o);

// Runs the measurement into out_dir (created). Progress lines go to spdlog. Throws config::ConfigError for
// a configuration that does not validate.
[[nodiscard]] MeasureOutcome measure(const std::string& config_path, const std::string& out_dir,
                                     const MeasureOptions& o = {});
// The same with a configuration in hand (config_path: where it is said to come from, for the manifest).
[[nodiscard]] MeasureOutcome measure(const config::Config& cfg, const std::string& config_path,
                                     const std::string& out_dir, const MeasureOptions& o = {});

// The exit code the commands use: 0 ok, 2 configuration, 4 tripped, 5 incomplete, 6 not ready, 7 the
// excitation saturated, 8 aborted by the operator, 1 otherwise.
[[nodiscard]] int exit_code(MeasureStatus s);

}  // namespace robodamp::commission
