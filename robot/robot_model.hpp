// The planar chain from a robot model file (config/robot_model_config.hpp), at a pose checked against
// the joints' travel.
#pragma once

#include <vector>

#include "config/robot_model_config.hpp"
#include "robot/planar_chain.hpp"

namespace robodamp::robot {

[[nodiscard]] ChainModel chain_model(const config::RobotModelConfig& cfg);
// Throws config::ConfigError (wrong count, a joint outside its travel) or std::invalid_argument.
[[nodiscard]] PlanarChain at_pose(const config::RobotModelConfig& cfg, const std::vector<double>& joints_deg);

}  // namespace robodamp::robot
