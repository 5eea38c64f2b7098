// The commissioning measurement along the robot's path (docs/pose_dynamics.md, "Measuring along the path"):
// one run of the loop, control off, while the robot program moves the robot from pose to pose. robodamp
// reads the joints from the robot (the Modbus joint registers or the DDS joint states) and finds each stop
// itself: when the joints have stood within still_deg for commissioning.settle_s and the cell is at rest,
// the loop's chirp plays (an on-command chirp, rt/excitation.hpp); the plant side's hammer (the HIL
// emulator's `plant --pose-at ... --measure-out DIR`) hits every location after it on the same timeline as
// a stopped measurement's. No manual stop, no --pose typed: the pose is the one the robot reported.
//
// Each stop the robot makes is a dwell, numbered from 1 in the order the robot makes them (the emulator
// numbers its trajectory's dwells the same way); a pause shorter than commissioning.settle_s is not a stop
// (no chirp could start there) and takes no number: DIR/dwell_<k>/ holds its measurement.json (the joints
// read during the chirp, the chirp's start in the run's recording), the run's recording (a hard link), and,
// from the plant side, its impact FRFs: each is a `robodamp measure` directory for `identify all`, and
// DIR/poses.json indexes them for `pose fit --measurements` and `pose modes --measurements`.
#pragma once

#include <string>
#include <vector>

#include "commission/measurement.hpp"

namespace robodamp::commission {

struct PathMeasureOptions {
  MeasureOptions measure;    // clock, impacts (the plant side's hammer), control_on; pose_deg must be empty
  int dwells{1};             // the run ends once this many dwells are measured
  double max_run_s{3600.0};  // ... or after this long, whatever was measured
  double still_deg{0.05};    // a joint further than this from the dwell's pose: the robot moves
};

struct DwellMeasurement {
  int index{0};                    // 1: the robot's first stop since the run began
  std::string name;                // dwell_<index>
  std::string dir;                 // absolute; empty when the dwell was not measured
  std::vector<double> joints_deg;  // the mean of the joints read during the chirp
  double still_s{0.0};             // loop time the joints stood still from
  double chirp_start_s{0.0}, chirp_end_s{0.0};
  double moved_s{-1.0};  // when the robot left (-1: it did not before the run ended)
  bool measured{false};
  std::string skipped;  // why not, when not measured
};

struct PathMeasureOutcome {
  MeasureOutcome run;                    // the run as a whole (status, message, state, trip, saturation, frames)
  std::vector<DwellMeasurement> dwells;  // every stop seen, measured or not
  int pauses{0};                         // stillness shorter than commissioning.settle_s: not a stop, no number
  [[nodiscard]] int measured() const;
};

// Throws config::ConfigError: no pose_schedule.model, or no joints to read (a robot that reports none:
// the simulated plant in process stands still), or --pose given.
[[nodiscard]] PathMeasureOutcome measure_along_path(const config::Config& cfg, const std::string& config_path,
                                                    const std::string& out_dir, const PathMeasureOptions& o);

}  // namespace robodamp::commission
