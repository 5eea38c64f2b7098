// The pose map behind `robodamp pose map` (docs/pose_dynamics.md): the robot model's first mode and its TCP
// modal stiffness over a grid of two joints' travel, and, with a milling job whose structure has a robot
// pose part, the job's minimum limiting depth at each pose (open loop, by the accurate method or the
// zero-order preview). Off the real-time path.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/milling_config.hpp"
#include "config/robot_model_config.hpp"

namespace robodamp::milling {

struct PoseMapPoint {
  std::vector<double> joints_deg;
  double f1_hz{0.0};
  double k1_n_per_m{0.0};               // the first mode's modal stiffness at the TCP
  std::optional<double> min_depth_mm;   // with a job: its minimum limiting depth over its speed range
  std::optional<double> min_depth_rpm;  // and where
};

struct PoseMapRequest {
  std::vector<double> base_deg;        // the other joints' angles
  std::size_t joint_a{1}, joint_b{2};  // the two joints varied over their travel (0-based)
  int steps{21};                       // grid steps per joint (>= 2)
  const config::MillingConfig* job{nullptr};
  bool zero_order{false};  // the job's depth by the zero-order preview (else the accurate method)
};

struct PoseMap {
  std::vector<PoseMapPoint> grid;  // joint_a's steps outer, joint_b's inner
  double f1_min_hz{0.0}, f1_max_hz{0.0};
  std::string method;  // with a job: "SDM" or "zero-order preview"
  double min_depth_min_mm{0.0}, min_depth_max_mm{0.0};
};

// progress(row, rows) after each of joint_a's steps when a job is mapped (each row takes a while). Throws
// config::ConfigError when the job's structure has no robot pose part.
[[nodiscard]] PoseMap pose_map(const config::RobotModelConfig& model, const PoseMapRequest& request,
                               const std::function<void(int row, int rows)>& progress = {});

struct PoseMapReport {
  nlohmann::json json;
  std::string text;
  std::string
      plot_data;  // per pose: joint a, joint b, f1, k1, the job's minimum depth (NaN without); rows blank-separated
};

// The map as `pose map` reports it: the grid, the first mode's range and, with a job (job_path), the minimum
// limiting depth's, with the method. vary: the two joints, 1-based.
[[nodiscard]] PoseMapReport pose_map_report(const config::RobotModelConfig& model, const PoseMapRequest& request,
                                            const PoseMap& map, const std::string& job_path);

// The map's plot (PNG): the first mode, its TCP stiffness and, with a job, the minimum depth over the two joints.
// An empty string, or what went wrong.
[[nodiscard]] std::string plot_pose_map(const PoseMapReport& r, const PoseMapRequest& request, const PoseMap& map,
                                        const std::string& png_path);

}  // namespace robodamp::milling
