// `robodamp pose tune` (docs/pose_dynamics.md, "Tuning across the workspace"): a robust set and a schedule
// drawn from the data, tuned over a configuration's pose_schedule workspace with a pose-indexed robot model,
// compared on the workspace map, the better written. The work is tune/pose_tune.* and tune/pose_score.*.
#pragma once

#include <string>
#include <vector>

#include "apps/cli.hpp"

namespace robodamp::apps {

struct PoseTuneArgs {
  std::string config_path;  // the cell, with a pose_schedule
  std::string model_path;   // the pose-indexed model; default pose_schedule.model
  std::vector<std::string> measurements, hold_out;
  std::string job_path;
  int evaluations{60}, polish{30}, max_regions{4}, map_points{9}, seed{1};
  double overlap_deg{4.0};
  double worse_mode_pct{0.0};  // a mode in the damping band this much worse than open loop still serves
  std::string out_path;
  JsonOut json;
};

// 0: written (or reported); 1: nothing serves (no stable set); 2: bad input.
int run_pose_tune(const PoseTuneArgs& a);

}  // namespace robodamp::apps
