// The commissioning measurement at several poses (docs/pose_dynamics.md, "Measuring across the
// workspace"): the poses of a file (a robot model file's poses:, or a file holding only poses:), each
// checked against the configuration's robot model before anything runs, then one `robodamp measure` per
// pose into DIR/<pose name>/ with its joint angles in measurement.json, and DIR/poses.json indexing them.
// The simulated plant stands at each pose in turn. On hardware (a `can` section) --poses is refused: the
// user moves the robot and runs `measure --pose` at each pose (the measurement cannot wait for a move).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "commission/measurement.hpp"
#include "config/robot_model_config.hpp"

namespace robodamp::commission {

struct PoseMeasurement {
  std::string name;
  std::vector<double> joints_deg;
  std::string dir;  // absolute
  MeasureOutcome outcome;
};

// The poses of poses_file against the configuration's pose_schedule.model. Throws config::ConfigError
// naming each refused pose and why (a joint outside its travel, the wrong count, a repeated name).
[[nodiscard]] std::vector<config::RobotPoseConfig> read_measurement_poses(const std::string& config_path,
                                                                          const std::string& poses_file);

// Measures at every pose in turn (stopping at the first that does not finish: its status says why) and
// writes out_dir/poses.json. `each` is called after each pose.
[[nodiscard]] std::vector<PoseMeasurement> measure_poses(const std::string& config_path,
                                                         const std::vector<config::RobotPoseConfig>& poses,
                                                         const std::string& out_dir, const MeasureOptions& o,
                                                         const std::function<void(const PoseMeasurement&)>& each = {});

// A directory name for a pose name: letters, digits, '-' and '_' kept, everything else '_'.
[[nodiscard]] std::string pose_dir_name(const std::string& pose_name);

}  // namespace robodamp::commission
