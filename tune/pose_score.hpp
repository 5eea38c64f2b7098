// Controllers for a pose_schedule scored on the workspace map (robodamp pose tune; docs/pose_dynamics.md,
// "Tuning across the workspace"): at every pose of a grid over the workspace and every measured and held-out
// pose, the sets that can run there (in an overlap either region's, the hand-over's hysteresis decides;
// the worst of them counts) against the pose-indexed model's plant:
//   - stable, the smallest improvement of any robot mode's peak (analysis/mode_improvement.hpp) in the
//     pose_schedule's damping band and outside it, and the driving point's improvement (discrete loop);
//   - with a milling job, its damped limiting depth by the accurate method (the sampled loop's
//     semi-discretization, the same checked speeds as tune's objective: the job's speed, the damped
//     zero-order lobes' lowest minima and the open loop's SDM minima), next to the open loop's.
// Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/pose_tune.hpp"

namespace robodamp::tune {

struct PoseScore {
  std::vector<std::string> regions;  // the sets that can run at the pose (none: outside every region, not scored)
  bool stable{false};
  double worst_mode_improvement_pct{0.0};  // of the modes in pose_schedule's damping band
  double worst_mode_hz{0.0};
  std::optional<double> outside_band_pct;  // the worst mode outside the damping band, if one is
  std::optional<double> outside_band_hz;
  double improvement_pct{0.0};                 // the driving point's peak (in an overlap the worse set's)
  std::vector<double> region_improvement_pct;  // each region's set in `regions`: the driving point's peak
  std::optional<double> damped_min_mm;         // with a job: sampled-loop SDM
  std::optional<double> damped_min_rpm;
};

struct ControllerScore {
  std::string name;              // "robust", "scheduled"
  std::vector<PoseScore> poses;  // in the map's order
  bool stable_everywhere{true};
  double worst_mode_improvement_pct{0.0};  // over the map, in the damping band
  std::optional<double> outside_band_pct;  // over the map, outside it
  std::optional<double> outside_band_hz;
  double worst_improvement_pct{0.0};
  std::optional<double> damped_min_mm;  // with a job: the smallest over the map
};

struct MapPose {
  NamedPose pose;
  std::string role;  // "grid", "measured", "held out"
  double dominant_hz{0.0};
  std::optional<double> open_min_mm;  // with a job: the open loop's smallest SDM limit at the checked speeds
};

struct MapScores {
  std::vector<MapPose> map;
  std::vector<ControllerScore> controllers;
  std::string method;  // of the depths: "sampled-loop SDM" (with a job)
};

// The map: a grid over the workspace (points per joint along the joints that move the dominant mode,
// tune/pose_tune.hpp's mode_grid), then the measured and the held-out poses.
[[nodiscard]] std::vector<MapPose> workspace_map(const PoseTuneInput& in, int points,
                                                 const std::vector<NamedPose>& held_out);

// Each named schedule (its regions' sets designed by analysis::design_region) scored at every map pose.
// A job's structure is replaced by the robot at the pose closed through the set (the TCP along the
// actuator's axis); its other parts are kept. Throws config::ConfigError for a job that cannot be analysed.
[[nodiscard]] MapScores score_on_map(const PoseTuneInput& in, std::vector<MapPose> map,
                                     const std::vector<std::pair<std::string, config::PoseScheduleConfig>>& schedules,
                                     const std::optional<config::MillingConfig>& job,
                                     const PoseTuneProgress& progress = {});

// The better controller: stable at every map pose; then keeping the damping band's promise (no mode in
// the band more than worse_mode_tolerance_pct worse than open loop at any map pose); then the larger
// smallest damped depth with a job (by more than 1 %); else the larger worst mode improvement (by more than
// 1 point). Ties go to the first (the robust one: no hand-overs).
[[nodiscard]] std::size_t better_controller(const MapScores& s, double worse_mode_tolerance_pct = 0.0);

}  // namespace robodamp::tune
