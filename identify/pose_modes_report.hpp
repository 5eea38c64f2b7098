// What `robodamp pose modes` reports (docs/pose_dynamics.md, "Modes between measured poses"): the map built
// from the modes measured at several poses, checked at the poses held out of it; or a mapped model's modes
// at one pose with their spread, and along one joint's travel for the plot. JSON, text and the plot's data.
// Off the real-time path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/robot_model_config.hpp"

namespace robodamp::identify {

struct PoseModesReport {
  nlohmann::json json;
  std::string text;
  std::optional<config::RobotModelConfig> mapped;  // the map: the model with its measured modes (for --out)
  std::string plot_data;                           // the sweep: per joint angle, each mode's model, map, band
  std::size_t curves{0};                           // the sweep's modes
  std::vector<bool> model_curve;                   // [mode]: the model has a mode it follows somewhere
};

// The modes identified in the measurement directories, the model's `modes` lowest corrected towards them, and
// each measured and held-out pose's modes against the model's and the map's.
[[nodiscard]] PoseModesReport pose_modes_map_report(const config::RobotModelConfig& model,
                                                    const std::vector<std::string>& measurements,
                                                    const std::vector<std::string>& hold_out, int modes);

// Throws config::ConfigError when the model has no measured modes (nothing to show between poses).
void require_measured_modes(const config::RobotModelConfig& model);

// A model with measured_modes at joints q: its `modes` lowest modes, mapped, each with its one sigma. Throws
// config::ConfigError when the model has no measured modes.
[[nodiscard]] PoseModesReport pose_modes_at_report(const config::RobotModelConfig& model, const std::vector<double>& q,
                                                   int modes);

// Adds the mapped modes along joint `vary_joint` (1-based; the others at q) to r: its JSON's "sweep", the plot's
// data. Throws std::invalid_argument for a joint the model does not have.
void add_pose_modes_sweep(PoseModesReport& r, const config::RobotModelConfig& model, const std::vector<double>& q,
                          int vary_joint, int modes);

// The sweep's plot (PNG): the map as lines with a 2-sigma band, the model alone dashed, the measured modes
// as points. Returns the reason it failed, or an empty string.
[[nodiscard]] std::string plot_pose_modes_sweep(const PoseModesReport& r, int vary_joint, const std::string& path);

}  // namespace robodamp::identify
