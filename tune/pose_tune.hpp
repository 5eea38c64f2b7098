// Tuning across the workspace (robodamp pose tune; docs/pose_dynamics.md, "Tuning across the workspace"):
// from a pose-indexed robot model (fitted to measurements, robodamp pose fit) and the poses measured, two
// controllers for a configuration's pose_schedule workspace:
//   - robust: one compensator tuned over the whole workspace;
//   - scheduled: regions drawn from the data: a region whose tuned set does not serve it (infeasible:
//     unstable, margins, the actuator's limits, or a robot mode's peak more than worse_mode_tolerance_pct
//     worse than open loop at one of its poses) is cut in two across the joint that moves its dominant mode
//     most, the halves overlapping by overlap_deg, and each half tuned again, until every region is served
//     or there are max_regions. The cut lies halfway from the region's centre to the pose where its set
//     stops serving (the worst case's pose), else where the dominant mode crosses the middle (geometric
//     mean) of its range along that joint; never closer than min_width_deg to the region's ends.
// A region's poses: a grid over it, grid_points per joint along the joints that change the plant there
// (over the joint's width, a mode's frequency by 1 % or a mode's peak receptance by 5 % of the largest
// peak), the centre along the others; a line of poses at most line_step_deg apart along each such joint;
// and every measured pose inside it.
// A set's objective is the smallest improvement of any robot mode's peak over the region's poses (max-min),
// under the tune's margins and actuator limits (tune/compensator_search.hpp; the damping window is left to
// the modes' peaks), its compensator's gain nowhere more than compensator_gain_max times its gain at the
// match frequency (a set that lifted the drift or the noise tripped on saturation in the HIL). It starts from
// the best of single-pose tunes (one plant each, three times the evaluations) at the region's centre and at
// its lowest and highest dominant mode, the shape whose feedback opposes the velocity at every mode in the
// band (tune/phase_start.hpp) at a few gains, and (a half of a cut region) the set of the region it was cut
// from, then is searched over all the region's poses from there at that polarity (tune::tune_from). The set
// is then checked between those poses (the line at half the step): a pose where it does not serve joins
// the region's poses and the search runs again from the set (twice at most); a region serves only where
// that check holds too. Both controllers are then scored on the workspace map (tune/pose_score.hpp) and the
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
  TuneSettings tune;           // no_worse_mode is set by the pose tune
  int max_regions{4};          // the scheduled controller's regions at most
  double overlap_deg{4.0};     // neighbouring regions overlap by this across the cut (the hand-over's hysteresis)
  double min_width_deg{8.0};   // a region is not cut along a joint narrower than twice this
  double line_step_deg{10.0};  // a region's poses along each joint that changes the plant at most this far apart
  double worse_mode_tolerance_pct{0.0};  // a mode's peak up to this much worse than open loop still serves
  double compensator_gain_max{10.0};     // TuneSettings::compensator_gain_max for every set
};

struct TunedRegion {
  config::PoseRegionConfig region;  // the box, with the tuned compensator, match frequency, gain and polarity
  Evaluation worst;                 // the tuned set's worst case over the region's poses
  std::vector<NamedPose> poses;     // where it was tuned: the grid and the measured poses inside
  double dominant_min_hz{0.0}, dominant_max_hz{0.0};
  [[nodiscard]] bool serves() const { return worst.feasible(); }
};

struct PoseTuneInput {
  config::Config cell;              // with a pose_schedule (model, axis, modes, grid_points, workspace)
  config::RobotModelConfig model;   // the pose-indexed model (pose_schedule.model or a fitted one)
  std::vector<NamedPose> measured;  // tuned at where inside a region
};

using PoseTuneProgress = std::function<void(const std::string&)>;

// A points^n grid over the box along the joints that move the dominant mode there (see above), the
// centre along the others; each pose once.
[[nodiscard]] std::vector<NamedPose> mode_grid(const PoseTuneInput& in, const config::PoseRegionConfig& r, int points);

// One set tuned over the box's poses; with a parent (the region it was cut from), the parent's set is one
// of the starts, so a half is never tuned worse over its poses than the set it replaces. Throws
// config::ConfigError for a pose outside the model's travel.
[[nodiscard]] TunedRegion tune_region(const PoseTuneInput& in, const std::string& name,
                                      const std::vector<double>& min_deg, const std::vector<double>& max_deg,
                                      const PoseTuneSettings& s, const PoseTuneProgress& progress = {},
                                      const TunedRegion* parent = nullptr);

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
