// What `robodamp pose fit` fits the robot model's joints to: measured TCP receptances at poses, given one by
// one as "Q1,Q2,...:FRF.csv" (joint angles in deg, a freq_hz,re_m_per_n,im_m_per_n[,coherence] CSV) or as a
// list of pose measurement directories (identify/pose_measurements.hpp), with the poses held out of the fit apart.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/robot_model_config.hpp"
#include "robot/pose_fit.hpp"

namespace robodamp::identify {

struct PoseFitInputs {
  std::vector<robot::MeasuredFrf> fit, held;
  std::optional<robot::FrfDirection> direction;  // from the measurements' configuration
  int modes{0};                                  // its pose_schedule.modes
};

// "Q1,Q2,...:path": the pose and the FRF read from path. Throws std::invalid_argument naming the item.
[[nodiscard]] robot::MeasuredFrf read_measured_frf(const std::string& item);

// The --measured items, then the directories' poses (checked against the model), the held-out names moved to
// `held` (pose fit and pose tune). Throws std::invalid_argument when a held-out name is not measured.
[[nodiscard]] PoseFitInputs read_pose_fit_inputs(const std::vector<std::string>& measured,
                                                 const std::vector<std::string>& measurement_dirs,
                                                 const std::vector<std::string>& hold_out,
                                                 const config::RobotModelConfig& model);

}  // namespace robodamp::identify
