// The modes identified at each measured pose (`robodamp pose modes`, docs/pose_dynamics.md, "Modes between
// measured poses"): each pose's driving-point receptance fitted (identify/modal_fit.hpp) in the measured
// configuration's analysis band, the modes in modal-stiffness form along the measured axis. They become a
// robot model file's measured_modes (robot/modal_map.hpp).
#pragma once

#include <string>
#include <vector>

#include "config/robot_model_config.hpp"
#include "identify/pose_measurements.hpp"

namespace robodamp::identify {

struct PoseModesIdentified {
  config::MeasuredModesConfig measured;             // the poses kept in the map
  std::vector<config::MeasuredPoseModes> held_out;  // identified as well, to check the map against
  std::vector<double> fit_error_pct;                // each pose's modal fit, in the order measured then held out
};

// Throws std::invalid_argument: a cross receptance (xy), a hold-out name that is no measured pose, every
// pose held out, or a pose whose FRF has no identifiable mode (naming it and the fit's reason).
[[nodiscard]] PoseModesIdentified identify_pose_modes(const PoseMeasurements& pm,
                                                      const std::vector<std::string>& hold_out);

}  // namespace robodamp::identify
