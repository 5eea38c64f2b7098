// The controller scheduled by pose (docs/pose_dynamics.md, "Scheduling by pose"): for each region of
// pose_schedule, the parameter set and its analysis, done once at configuration time.
//   - The plant at a pose is the robot model's lowest modes at the TCP along the actuator's axis
//     (modal-stiffness form; every configured FRF path becomes that TCP receptance: the actuator and
//     the accelerometer sit on the spindle head, at the TCP).
//   - A region's set is the configuration with the plant at the region's centre, the compensators
//     matched at that pose's dominant mode, the polarity the analysis recommends there and the region's
//     gain; a tuned region (robodamp pose tune) gives its own compensator, pre-warp frequency and
//     polarity. The set is then analysed against the plant at every pose of a grid over the region (grid_points
//     per joint). The set's K_max is the smallest found; a pose where the set is unstable, or where its
//     gain is above supervision.max_gain_fraction x K_max, refuses the whole configuration, naming the
//     region, the pose and the reason.
// Off the real-time path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/robot_model_config.hpp"
#include "robot/modal_map.hpp"

namespace robodamp::analysis {

// The robot model's modes at a pose along one axis, lowest first. When the model file has measured_modes
// (robodamp pose modes), they are the mapped modes (robot::ModalMap), lowest first, each with its uncertainty.
struct PoseModes {
  std::vector<config::ModeConfig> modes;           // modal-stiffness form, damping from each mode's loss factor / 2
  std::size_t dominant{0};                         // the largest peak receptance along the axis (smallest k zeta)
  std::vector<robot::ModeCorrection> corrections;  // one per mode; empty: the model alone
  double nearest_measured_deg{0.0};  // with corrections: the joint-space distance to the nearest measured pose
  [[nodiscard]] double dominant_hz() const { return modes.empty() ? 0.0 : modes[dominant].natural_freq_hz; }
};
// Throws config::ConfigError (a pose outside the travel) or std::invalid_argument (a non-physical model, or
// measured_modes along another axis).
[[nodiscard]] PoseModes pose_modes(const config::RobotModelConfig& model, const std::vector<double>& joints_deg,
                                   int axis, int count);

// The middle of the region's box.
[[nodiscard]] std::vector<double> region_centre(const config::PoseRegionConfig& r);

// base with the robot's table replaced by the model's lowest `count` modes at the pose in its plane: location
// 1 the TCP along `axis` (the actuator and the sensor there), location 2 the TCP along the other axis, the
// tables H11, H21 and H22 (modal-stiffness form, mass-normalised TCP shapes; a cross term's stiffness is
// negative where the shapes' signs differ). Its loop is the 1-D set's (H11 is pose_modes' table); the cut
// sees the robot in both directions (milling::LiveStability at a pose). Throws as pose_modes.
[[nodiscard]] config::Config config_in_plane_at_pose(const config::Config& base, const config::RobotModelConfig& model,
                                                     const std::vector<double>& joints_deg, int axis, int count);

// Every pose of a points^n grid over the region's box (its ends included; points >= 2).
[[nodiscard]] std::vector<std::vector<double>> region_grid(const config::PoseRegionConfig& r, int points);

// base with the robot's modal table replaced by the model's at the pose (every location at the TCP,
// axis_sign +1).
[[nodiscard]] config::Config config_at_pose(const config::Config& base, const PoseModes& modes);

// The set's chain with the region's own compensator in place of the compensator block. Throws
// config::ConfigError when the chain has none.
void with_region_compensator(config::Config& set, const config::RegionCompensatorConfig& c);

struct RegionSet {
  std::string name;
  std::vector<double> centre_deg;
  double dominant_hz{0.0};  // at the centre: the compensators' match frequency
  double gain_ns_per_m{0.0};
  int polarity{1};                                    // recommended by the analysis at the centre
  config::Config config;                              // the set (plant at the centre)
  double k_max_ns_per_m{0.0};                         // smallest over the grid
  std::vector<double> k_max_pose_deg;                 // where
  double dominant_min_hz{0.0}, dominant_max_hz{0.0};  // over the grid
  double improvement_centre_pct{0.0};  // predicted driving-point improvement at the centre (discrete loop)
  // The smallest improvement of any robot mode's peak in pose_schedule's damping band over the grid
  // (analysis/mode_improvement.hpp): negative where the set makes a mode worse than open loop; where and
  // which mode. Outside the band: the smallest, if a mode lies there.
  double worst_mode_improvement_pct{0.0};
  double worst_mode_hz{0.0};
  std::vector<double> worst_mode_pose_deg;
  std::optional<double> outside_band_pct, outside_band_hz;
  int grid_poses{0};
};

struct PoseScheduleAnalysis {
  config::RobotModelConfig model;
  std::vector<RegionSet> regions;
};

// Region i's set alone (not yet checked over its grid): its configuration, match frequency and polarity.
[[nodiscard]] RegionSet design_region(const config::Config& cfg, const config::RobotModelConfig& model, std::size_t i);

// Throws config::ConfigError naming the region, the pose and the reason when a region has no stable set.
[[nodiscard]] PoseScheduleAnalysis analyse_pose_schedule(const config::Config& cfg);

class LoopModel;
// The driving-point improvement of a loop (discrete, %): how much the peak of the actuator location's
// receptance drops with the loop closed at this gain and polarity.
[[nodiscard]] double driving_point_improvement_pct(const LoopModel& m, double gain_ns_per_m, int polarity);

// The driving-point improvement the analysis predicts for a set at a pose (discrete loop, %): how much
// the peak of the actuator location's receptance drops with the loop closed.
[[nodiscard]] double predicted_improvement_pct(const config::Config& set, const config::RobotModelConfig& model,
                                               const config::PoseScheduleConfig& schedule,
                                               const std::vector<double>& joints_deg);

// The same prediction with the uncertainty the model gives it at the pose. On a mapped model (measured_modes)
// each mapped mode's frequency, damping ratio and stiffness along the axis carries its map's one-sigma spread
// (robot::ModeCorrection: the frequency's and the damping's of their logarithms, the stiffness's of its
// participation w^2 / k relative to it; 0 for the model's modes no measurement follows); the improvement's own
// one sigma is propagated to first order from them as independent: the root sum of squares of half the change
// between each quantity at plus and minus one sigma (every mode counts: the peak may move to another one).
// Near a measured pose it is the measurement's noise; between measured poses it grows with the map's spread.
// Without measured_modes it is 0 (the model file states no uncertainty).
struct PredictedImprovement {
  double pct{0.0};
  double sigma_pct{0.0};  // points of improvement, one sigma
};
[[nodiscard]] PredictedImprovement predicted_improvement(const config::Config& set,
                                                         const config::RobotModelConfig& model,
                                                         const config::PoseScheduleConfig& schedule,
                                                         const std::vector<double>& joints_deg);

}  // namespace robodamp::analysis
