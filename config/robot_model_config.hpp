// A robot model file (config/robots/*.yaml; docs/pose_dynamics.md): the planar chain's links, joints,
// head and named poses, every number with its unit and allowed range. Read by robot/ and the pose
// commands. The joint angles of a pose are relative (each link to the previous; joint 1 to the base's x).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace robodamp::config {

struct RobotLinkConfig {
  double length_m{1.0};
  double mass_kg{10.0};
  double bending_stiffness_nm2{1e7};
  double axial_stiffness_n{1e9};
  int elements{4};
};

struct RobotJointConfig {
  double stiffness_nm_per_rad{1e5};
  double damping_ratio{0.02};
  double min_deg{-180.0}, max_deg{180.0};       // the joint's travel: a pose outside it is refused
  double translational_stiffness_n_per_m{0.0};  // its bearings in x and y; 0 (the default): rigid
};

struct RobotPoseConfig {
  std::string name;
  std::vector<double> joints_deg;
  std::optional<double> measured_f1_hz, predicted_f1_hz;  // published values to report beside the model's
};

// The modes identified at one measured pose along the measured axis (modal-stiffness form), lowest first.
struct MeasuredPoseModes {
  std::string name;
  std::vector<double> joints_deg;
  std::vector<ModeConfig> modes;
};

// Modes measured across the workspace (`robodamp pose modes --out`): the model's modes at a pose are
// corrected towards them (robot/modal_map.hpp; docs/pose_dynamics.md, "Modes between measured poses").
struct MeasuredModesConfig {
  int axis{1};  // 0: x, 1: y: the TCP direction they were measured along
  std::vector<MeasuredPoseModes> poses;
};

struct RobotModelConfig {
  std::string source;
  std::string name;
  std::vector<RobotLinkConfig> links;
  std::vector<RobotJointConfig> joints;
  double head_mass_kg{0.0};
  double head_inertia_kgm2{0.0};
  std::vector<RobotPoseConfig> poses;
  std::optional<MeasuredModesConfig> measured_modes;
};

// Throws ConfigError holding every problem (key, value, unit, allowed range).
[[nodiscard]] RobotModelConfig parse_robot_model(const std::string& yaml_text, const std::string& source_name);
[[nodiscard]] RobotModelConfig load_robot_model(const std::string& path);
// The poses: list of a file (a robot model file, or one with only poses:), each checked against the
// model's joints; names must differ. Throws ConfigError naming each pose and its problem.
[[nodiscard]] std::vector<RobotPoseConfig> parse_pose_list(const std::string& yaml_text, const std::string& source_name,
                                                           const RobotModelConfig& model);
// A pose against the model's joints: the count and each joint's travel; nothing when it fits.
[[nodiscard]] std::optional<std::string> pose_problem(const RobotModelConfig& m, const std::vector<double>& joints_deg);

}  // namespace robodamp::config

namespace robodamp::config {
// The model as a robot model file (what parse_robot_model reads back).
[[nodiscard]] std::string robot_model_yaml(const RobotModelConfig& m);
}  // namespace robodamp::config
