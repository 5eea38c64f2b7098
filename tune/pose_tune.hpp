// Tuning across the workspace (robodamp pose tune; docs/pose_dynamics.md, "Tuning across the workspace"):
// from a pose-indexed robot model (fitted to measurements, robodamp pose fit) and the poses measured, two
// controllers for a configuration's pose_schedule workspace:
//   - robust: one compensator tuned over the whole workspace (the worst case over a grid of its poses and
//     every measured pose inside it);
//   - scheduled: regions drawn from the data: a region whose best tuned set does not serve it (infeasible:
//     unstable, margins, the damping window, the actuator's limits, or a robot mode's peak worse than open
//     loop at one of its poses) is cut in two across the joint that moves its dominant mode most, the halves
//     overlapping by overlap_deg, and each half tuned again, until every region is served or max_regions.
//     The cut lies where the dominant mode crosses the middle (geometric mean) of its range along that
//     joint: on a robot whose two modes trade places, between them.
// A region's poses are a grid over it: grid_points per joint along the joints that move the robot's
// modes there (frequency by 1 % or modal stiffness by 5 % over the joint's width), the centre along the
// others; and every measured pose inside it.
// Each set is tuned by tune::tune (its objective: the largest closed-loop receptance peak over the region's
// poses; no_worse_mode always on). Both are then scored on the workspace map (tune/pose_score.hpp) and the
// better written. Off the real-time path.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "config/robot_model_config.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp::tune {

struct NamedPose {
  std::string name;
  std::vector<double> joints_deg;
};

struct PoseTuneSettings {
  TuneSettings tune;         // no_worse_mode is set by the pose tune
  int max_regions{4};        // the scheduled controller's regions at most
  double overlap_deg{4.0};   // neighbouring regions overlap by this across the cut (the hand-over's hysteresis)
  double min_width_deg{8.0}; // a region is not cut along a joint narrower than twice this
  double worse_mode_tolerance_pct{1.0};  // a mode's peak up to this much worse than open loop still serves
};

struct TunedRegion {
  config::PoseRegionConfig region;  // the box, with the tuned compensator, match frequency, gain and polarity
  Evaluation worst;                 // the tuned set's worst case over the region's poses
  std::vector<NamedPose> poses;     // where it was tuned: the grid and the measured poses inside
  double dominant_min_hz{0.0}, dominant_max_hz{0.0};
  [[nodiscard]] bool serves() const { return worst.feasible(); }
};

struct PoseTuneInput {
  config::Config cell;                    // with a pose_schedule (model, axis, modes, grid_points, workspace)
  config::RobotModelConfig model;         // the pose-indexed model (pose_schedule.model or a fitted one)
  std::vector<NamedPose> measured;        // tuned at where inside a region
};

using PoseTuneProgress = std::function<void(const std::string&)>;

// A points^n grid over the box along the joints that move the dominant mode there (see above), the
// centre along the others; each pose once.
[[nodiscard]] std::vector<NamedPose> mode_grid(const PoseTuneInput& in, const config::PoseRegionConfig& r, int points);

// One set tuned over the box's poses. Throws config::ConfigError for a pose outside the model's travel.
[[nodiscard]] TunedRegion tune_region(const PoseTuneInput& in, const std::string& name, const std::vector<double>& min_deg,
                                      const std::vector<double>& max_deg, const PoseTuneSettings& s,
                                      const PoseTuneProgress& progress = {});

// The robust controller: one region, the workspace.
[[nodiscard]] TunedRegion tune_robust(const PoseTuneInput& in, const PoseTuneSettings& s,
                                      const PoseTuneProgress& progress = {});

// The scheduled controller, starting from the robust set (its first region: the whole workspace).
[[nodiscard]] std::vector<TunedRegion> tune_schedule(const PoseTuneInput& in, const TunedRegion& robust,
                                                     const PoseTuneSettings& s, const PoseTuneProgress& progress = {});

// The cell's pose_schedule with these regions (what the configuration runs).
[[nodiscard]] config::PoseScheduleConfig schedule_of(const config::PoseScheduleConfig& base,
                                                     const std::vector<TunedRegion>& regions);

}  // namespace robodamp::tune
