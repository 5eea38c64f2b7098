// The controller scheduled by the robot's pose (docs/pose_dynamics.md, "Scheduling by pose"): boxes of
// joint angles (regions), each with its own parameter set, designed and analysed at configuration time
// from the robot model (config/robots/*.yaml) at the region's poses. Read by analysis/pose_schedule
// (the sets), runtime/ (the hand-over) and drivers/modbus_client (the joint registers).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace robodamp::config {

// A region's own compensator (what `robodamp pose tune` writes): a rational transfer function in s, highest
// power first, in place of the chain's compensator block in the region's set.
struct RegionCompensatorConfig {
  std::vector<double> numerator, denominator;
};

struct PoseRegionConfig {
  std::string name;
  std::vector<double> min_deg, max_deg;  // a box in joint space, one entry per joint
  std::optional<double> gain_ns_per_m;   // default controller.gain_ns_per_m
  // A tuned set: the compensator, its pre-warp frequency and the polarity. Without them the set is matched
  // at the region's dominant mode and the polarity is the one the analysis recommends there.
  std::optional<RegionCompensatorConfig> compensator;
  std::optional<double> match_freq_hz;  // default the dominant mode at the region's centre
  std::optional<int> polarity;
};

struct PoseScheduleConfig {
  std::string model;           // the robot model file, as written
  std::string model_resolved;  // resolved against the configuration file
  int axis{1};                 // the actuator's direction in the model's plane: 0 = x, 1 = y
  int modes{3};                // the robot's lowest modes put in the loop's plant
  int grid_points{3};          // per joint over each region (2: its corners; 3: and the middle ...)
  // The damping band: the robot modes the schedule damps and promises never to make worse than open loop
  // (the serving check, the tuned sets' objective, the schedule's report). A loop that damps one band lifts
  // the response somewhere else (Bode's sensitivity integral, docs/pose_dynamics.md); outside this band the
  // reports show by how much. Default: every mode in the plant.
  double damping_band_min_hz{0.0}, damping_band_max_hz{1e9};
  std::vector<double> workspace_min_deg, workspace_max_deg;  // the regions must cover it (no holes)
  std::vector<PoseRegionConfig> regions;
  [[nodiscard]] std::size_t joints() const { return workspace_min_deg.size(); }
};

// The region for a pose: the current one while the pose stays inside it (regions that overlap give the
// hand-over its hysteresis), else the first that holds it; nothing when the pose is outside the
// workspace or every region, or any angle is not finite. No allocation.
[[nodiscard]] std::optional<std::size_t> region_of(const PoseScheduleConfig& s, const double* joints_deg,
                                                   std::size_t count, std::optional<std::size_t> current = {});
[[nodiscard]] bool region_holds(const PoseRegionConfig& r, const double* joints_deg, std::size_t count);
// A pose of the workspace no region holds (a hole in the map), if there is one. Exact: it tests one
// point inside each cell of the grid the boxes' faces cut the workspace into.
[[nodiscard]] std::optional<std::vector<double>> uncovered_pose(const PoseScheduleConfig& s);
// "[a, b, c] deg"
[[nodiscard]] std::string describe_pose(const std::vector<double>& joints_deg);

// A pose source's settling (the Modbus joint registers, a DDS joint state): a region (-1: out of the map) is
// reported once it has been seen `needed` times in a row and differs from the one reported.
struct PoseSettling {
  long candidate{-2}, reported{-2};  // -2: nothing yet
  int same{0};
  // True when region has now settled and is to be reported (then it is the reported one).
  [[nodiscard]] bool settled(long region, int needed) {
    same = region == candidate ? same + 1 : 1;
    candidate = region;
    if (same < needed || region == reported) return false;
    reported = region;
    return true;
  }
  void restart() { candidate = -2, same = 0; }
  [[nodiscard]] std::optional<std::size_t> current() const {
    return reported >= 0 ? std::optional(static_cast<std::size_t>(reported)) : std::nullopt;
  }
};

}  // namespace robodamp::config
