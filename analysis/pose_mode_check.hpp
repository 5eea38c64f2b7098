// The modes at measured poses beside the model's and the modal map's there (`robodamp pose modes`,
// docs/pose_dynamics.md, "Modes between measured poses"): at a pose held out of the map this is the map's
// check; at a pose in it, how closely the map passes through its own data.
#pragma once

#include <string>
#include <vector>

#include "config/robot_model_config.hpp"

namespace robodamp::analysis {

struct ModeCheckRow {
  std::string pose;
  std::vector<double> joints_deg;
  bool held_out{false};
  double measured_hz{0.0}, measured_damping_ratio{0.0}, measured_stiffness_n_per_m{0.0};
  // The model's nearest mode (within 25 %; NaN when none), and the mapped one with one standard deviation.
  double model_hz{0.0}, model_stiffness_n_per_m{0.0};
  double mapped_hz{0.0}, mapped_damping_ratio{0.0}, mapped_stiffness_n_per_m{0.0};
  double freq_sigma_pct{0.0}, damping_sigma_pct{0.0}, stiffness_sigma_pct{0.0};
  double nearest_measured_deg{0.0};  // from the pose to the nearest pose in the map
};

// prior: the model alone (no measured_modes); mapped: the same model with them. One row per measured mode.
[[nodiscard]] std::vector<ModeCheckRow> check_pose_modes(const config::RobotModelConfig& prior,
                                                         const config::RobotModelConfig& mapped,
                                                         const std::vector<config::MeasuredPoseModes>& poses,
                                                         bool held_out, int axis, int count);

// The modes along one joint's travel, the others held at base_deg: the model's and the mapped ones with their
// one-sigma frequency spread (the picture of where the measurements hold the map and where the model alone
// speaks). joint: 0-based; steps >= 2 over the joint's travel. model_hz[k] is the model's mode that mapped mode k
// follows (its correction's model index), NaN where the map has it from the measurements alone.
struct ModeSweepPoint {
  double joint_deg{0.0};
  std::vector<double> model_hz, mapped_hz, freq_sigma_pct;
};
[[nodiscard]] std::vector<ModeSweepPoint> sweep_pose_modes(const config::RobotModelConfig& prior,
                                                           const config::RobotModelConfig& mapped,
                                                           const std::vector<double>& base_deg, std::size_t joint,
                                                           int steps, int axis, int count);

}  // namespace robodamp::analysis
