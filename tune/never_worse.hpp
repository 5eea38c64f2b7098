// Never worse than no damper at the job's speed, pose by pose (commission --along-path; docs/pose_dynamics.md,
// "Commissioning along the path"): a pose schedule's set that makes the job's limiting depth at its speed
// shallower than the open loop's somewhere in its region is turned off there. Along the joint the region is
// widest in, the set is checked every step_deg on the line through the region's centre (and at every extra
// pose inside it); each run of poses where it is worse (damped below kNotWorse x the open loop of the same
// plant, milling::LiveStability at the pose) becomes a region of its own at K = 0, one step wider on each side,
// and the set keeps the rest, overlapping the off region by one step (the hand-over's hysteresis runs the set
// into the overlap only where it was checked not worse). Where what is left of the set is narrower than two
// steps, or a worse extra pose lies off the line's runs, the whole region is turned off. A region whose
// set is already K = 0 is left as it is. The tune scores the job's smallest damped depth over its map, not
// the depth pose by pose against the open loop: on the planar robot's wall cut at 700 rpm the robust set
// multiplied the limit 3-5 times over joint 2 = 40-110 deg and took 2-6 % off it at 30-35 deg.
// Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"

namespace robodamp::tune {

inline constexpr double kNotWorse = 0.995;  // a damped limit at least this share of the open loop's is not worse

struct NeverWorse {
  std::vector<config::PoseRegionConfig> regions;  // the schedule to run (unchanged where no set was worse)
  std::vector<std::string> notes;                 // each change, with the pose and the loss it removes
  [[nodiscard]] bool changed() const { return !notes.empty(); }
};

// cell: a configuration with a pose_schedule (its sets analysed as analysis::analyse_pose_schedule does);
// job: the cut (its structure replaced by the robot at each pose, milling::LiveStability); extra_poses: poses
// the set must also not be worse at (the workspace map's, the stops). Throws config::ConfigError.
[[nodiscard]] NeverWorse never_worse_at_speed(const config::Config& cell, const config::MillingConfig& job, double rpm,
                                              const std::vector<std::vector<double>>& extra_poses,
                                              double step_deg = 2.5);

}  // namespace robodamp::tune
