// `robodamp pose modes` (docs/pose_dynamics.md, "Modes between measured poses"):
//   with --measurements: the modes identified at each measured pose (identify/pose_modes.hpp) written into
//     the model file as its measured_modes (--out), and the map checked at the --hold-out poses;
//   without: the modes of a model with measured_modes at a pose (--joints or --pose), each with its
//     uncertainty, and the distance to the nearest measured pose.
#pragma once

#include <string>
#include <vector>

#include "apps/cli.hpp"
#include "config/robot_model_config.hpp"

namespace robodamp::apps {

struct PoseModesArgs {
  std::vector<std::string> measurements, hold_out;
  std::vector<double> joints_deg;  // the pose to show (empty: pose_name, else the model's first pose)
  std::string pose_name;
  int modes{3};  // without measurements: how many of the model's modes
  std::string out_path;
  JsonOut json;
  std::string plot_path;  // without measurements: the modes along one joint's travel (PNG)
  int vary_joint{2};      // that joint (1-based); the others at the pose shown
};

// 0: done; 1: cannot write; 2: bad input (reported on stderr by the caller's handler: throws).
int run_pose_modes(const config::RobotModelConfig& model, const PoseModesArgs& a);

}  // namespace robodamp::apps
