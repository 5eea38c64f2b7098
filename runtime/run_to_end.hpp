// `robodamp run`'s lifecycle: the cell built from a configuration and the run's options, taken through
// configure, activate, run, deactivate and cleanup, and the exit status its summary stands for (docs/cli.md).
// The command prints the summary; this says why it could not run.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "runtime/run_summary.hpp"

namespace robodamp::runtime {

// What `robodamp run` was asked for, as given on its command line.
struct RunRequest {
  std::string config_path;
  double duration_s{10.0};
  std::string record_path;
  std::string clock;  // "wall", "virtual" or empty: loop.clock
  double impact_every_s{2.0};
  std::string job_path;  // overrides spindle.job
  double spindle_rpm{0.0};
  bool no_harmonic_notch{false};
  std::vector<double> pose_deg;  // pose_schedule, simulated plant: the robot stands here
  bool no_pose_schedule{false};
  std::vector<std::string> faults;  // simulated plant: KIND:START_S[:DURATION_S] (sim_plant/fault_text.hpp)
};

// The run's summary once the cell ran (its exit status: run_exit_status), or the exit status when it could not
// run, the reason written to `err`: 2 a configuration or option error, 1 a device.
struct RunOutcome {
  std::optional<RunSummary> summary;
  int status{0};
};
[[nodiscard]] RunOutcome run_to_end(const RunRequest& request, std::ostream& err);

// 0 ended safe (disarmed, or shut down by a signal); 4 ended in a fault trip; 5 never armed (the arming policy's
// deadline passed, or the run ended first, said on `err`); 1 the recording failed.
[[nodiscard]] int run_exit_status(const RunSummary& s, std::ostream& err);

}  // namespace robodamp::runtime
