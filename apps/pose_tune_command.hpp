// `robodamp pose tune` (docs/pose_dynamics.md, "Tuning across the workspace"): a robust set and a schedule
// drawn from the data, tuned over a configuration's pose_schedule workspace with a pose-indexed robot model,
// compared on the workspace map, the better written. The work is tune/pose_tune.* and tune/pose_score.*.
#pragma once

#include "apps/cli.hpp"
#include "tune/pose_tune_file.hpp"

namespace robodamp::apps {

struct PoseTuneArgs : tune::PoseTuneCommand {
  JsonOut json;
};

// 0: written (or reported); 1: nothing serves (no stable set); 2: bad input.
int run_pose_tune(const PoseTuneArgs& a);

}  // namespace robodamp::apps
