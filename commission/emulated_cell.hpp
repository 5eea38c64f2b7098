// Commissioning through the HIL emulator (docs/identification.md, "Through the HIL emulator"): for a cell
// whose frames go over the emulator's transport (can.interface unix:...), `robodamp commission` starts
// `robodamp plant` as a second process for each run on the cell and runs the controller side itself,
// through the CAN and Modbus drivers, in lockstep (the emulator steps once per command frame, the loop runs
// on its virtual clock):
//   measure  the emulator's commissioning impacts (--measure-out) while the loop plays the chirp;
//   verify   the same impacts with the tuned controller running (the measurement is the control-off run),
//            and the regenerative cut in the emulator (hil/regenerative_cut.hpp) at each promised speed at
//            the promise less the tolerance, with the tuned controller: it must not chatter.
// Off the real-time path.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <sys/types.h>
#include <vector>

#include "commission/cell_check.hpp"
#include "commission/measurement.hpp"
#include "commission/path_measurement.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/verification.hpp"

namespace robodamp::commission {

// The robodamp executable that runs this process, to start again as the emulator (/proc/self/exe).
[[nodiscard]] std::string this_executable();

// A child process `BINARY ARGS...`, its output to a log file; killed and reaped if it is still running when
// destroyed (no emulator outlives a failed stage).
class EmulatorProcess {
 public:
  EmulatorProcess(const std::string& binary, const std::vector<std::string>& args, const std::string& log_path);
  ~EmulatorProcess();
  EmulatorProcess(const EmulatorProcess&) = delete;
  EmulatorProcess& operator=(const EmulatorProcess&) = delete;
  // Its exit code, or -1 if it had not ended within timeout_s (it is killed then).
  int wait(double timeout_s);
  [[nodiscard]] const std::string& log_path() const { return log_; }
  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] std::string log_tail(std::size_t lines = 6) const;

 private:
  pid_t pid_{-1};
  bool reaped_{false};
  std::string log_;
};

// Whether a cell is commissioned through the emulator: its can.interface is the emulator's unix: socket.
// A cell with another interface (a real CAN bus) has no hammer and no cut that robodamp drives: without tap
// tests it is refused with this reason (empty: through the emulator, or the simulated plant without can:).
[[nodiscard]] std::string hardware_refusal(const config::Config& cell);

// robodamp measure's run with the emulator as the plant side (it writes the impact FRFs into out_dir). With
// options.impacts false the emulator is a real cell: no impacts served, no cut; only the actuator's chirp.
// controller: the loop's configuration (none: the cell's own; the verification's tuned controller on the
// cell's wires otherwise).
struct EmulatedMeasure {
  MeasureOptions options;
  std::optional<config::Config> controller;
};
[[nodiscard]] MeasureOutcome measure_through_emulator(const std::string& cell_path, const std::string& out_dir,
                                                      const std::string& binary, const EmulatedMeasure& e = {});

// measure_along_path with the emulator as the robot and its hammer: `robodamp plant --pose-at ...
// --measure-out DIR` moves the robot through the trajectory (T:Q1,Q2,... waypoints) and hammers at each stop;
// the controller side finds the stops from the joint registers. Throws std::runtime_error when the emulator
// fails or does not end.
[[nodiscard]] PathMeasureOutcome measure_along_path_through_emulator(
    const config::Config& cell, const std::string& cell_path, const std::string& out_dir, const std::string& binary,
    const std::vector<std::string>& trajectory, const PathMeasureOptions& o);

// A controller run along the trajectory through the emulator, which at each dwell hits the driving point with
// the controller running and again on the robot standing there with the amplifier off (hil/pose_trajectory.hpp).
struct EmulatedDwell {
  std::vector<double> joints_deg;
  double t0_s{0.0}, t1_s{0.0};
  int records{0};
  double measured_improvement_pct{0.0};
  double coherence_min{0.0};
  double dominant_hz{0.0};
};
struct EmulatedPathRun {
  std::string trip{"none"};
  double active_share{0.0};  // of the ticks after the first settle
  unsigned long long saturated_ticks{0}, pose_out_of_map{0};
  std::vector<EmulatedDwell> dwells;
};
// duration_s: the run's loop time (the trajectory's last waypoint). Files and logs in dir. Throws
// std::runtime_error when the controller cannot reach the emulator, the lockstep stalls or the emulator fails.
[[nodiscard]] EmulatedPathRun run_along_path_through_emulator(const config::Config& controller,
                                                              const std::string& cell_path, const std::string& binary,
                                                              const std::vector<std::string>& trajectory,
                                                              double duration_s, const std::string& dir);

struct EmulatedCheckFiles {
  std::string binary;
  std::string cell_path, job_path;
  std::string measurement_dir;  // the control-off impacts (the measure stage's FRFs)
  std::string work_dir;         // the runs' FRFs, logs and reports
  int cut_revolutions{300};     // each regenerative cut's; 300: a slow decay is not read as chatter
};

// One regenerative cut in the emulator (drive vibration off) at a speed and depth, with `controller` (a
// configuration for the same wires) on the controller side from the loop at full gain; files in dir.
struct EmulatedCut {
  std::string binary, cell_path, job_path;
  int revolutions{300};
  // Wall time without a fresh sensor sample after which the run ends as stalled (every run's, the cut's its
  // own): a run under a CPU hog on both cores steps at about plant speed, and each missing frame costs the
  // loop its 1 s lockstep wait, so a silent emulator would otherwise hold the caller for hours.
  double stall_wall_s{30.0};
};
[[nodiscard]] CutTrial cut_through_emulator(const config::Config& cell, const config::Config& controller,
                                            const EmulatedCut& cut, double rpm, double depth_mm,
                                            const std::string& dir);

// The critical depth at a speed through the emulator by bisection on such cuts (from a guess, doubled or
// halved until the verdict changes, then halved to rel_tol), as milling::critical_depth does in process.
// Throws std::runtime_error when the controller trips or a cut does not complete.
struct EmulatedCritical {
  double rpm{0.0};       // the emulator's (a whole number of loop periods per tooth)
  double depth_mm{0.0};  // the largest stable depth found
  std::string above;     // the verdict just above it
  double chatter_hz{0.0};
  int cuts{0};
};
[[nodiscard]] EmulatedCritical critical_through_emulator(const config::Config& cell, const config::Config& controller,
                                                         const EmulatedCut& cut, double rpm, double guess_mm,
                                                         double rel_tol, const std::string& dir,
                                                         const std::function<void(const std::string&)>& progress = {});

// check_on_cell's checks through the emulator: improvement from the measure stage's FRFs (off) and the
// verify run's (on); the damped cut as a verdict at the promise less depth_tolerance at each speed.
[[nodiscard]] CellCheck check_through_emulator(const config::Config& cell, const config::Config& tuned,
                                               const tune::Verification& promise, const EmulatedCheckFiles& files);

}  // namespace robodamp::commission
