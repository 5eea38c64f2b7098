// `robodamp commission --along-path` (docs/pose_dynamics.md, "Commissioning along the path"): a
// pose-scheduled cell commissioned from measurements the robot makes as its program moves it, with no manual
// stop and no pose typed:
//   1 measure   one run, control off, while the robot moves from stop to stop: at each, the chirp and the
//               plant side's impacts (commission/path_measurement.hpp); the HIL emulator moves the robot
//               through the trajectory given (robodamp plant --pose-at) and hammers at each stop
//   2 identify  each stop on its own (identify all: the actuator, every FRF's modes); the driving point's
//               modes at every stop into the robot model file (measured_modes) and the map between them
//               (robot/modal_map.hpp), checked at the stops held out of it
//   3 tune      the robust set and the schedule drawn from the data, tuned and scored on the mapped model over
//               the configuration's workspace with the job, the better chosen (tune/pose_tune_file.hpp)
//   4 verify    the chosen controller run along the same path on the cell: at every stop the improvement the
//               impacts measure against the map's prediction there, no trip, no pose out of the map; and at
//               every stop the job at its speed, damped against open loop by the accurate method
//   5 write     DIR/configuration.yaml only when every check held; DIR/report.html and report.json always.
// Off the real-time path.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/pose_mode_check.hpp"
#include "commission/commission.hpp"
#include "commission/path_measurement.hpp"
#include "tune/pose_tune_file.hpp"

namespace robodamp::commission {

struct PathCommissionSettings {
  std::string config_path;      // the cell, with a pose_schedule (its model is the prior between the stops)
  Stage from{Stage::kMeasure};  // the stages before it reuse DIR's files (identify always runs again: quick)
  std::string job_path;
  std::string out_dir;
  int dwells{3};                        // the stops to measure
  std::vector<std::string> hold_out;    // stops (dwell_<k>) kept out of the map, checked against it
  std::vector<std::string> trajectory;  // the HIL emulator's robot path: T:Q1,Q2,... (robodamp plant --pose-at)
  double still_deg{0.05};
  double max_run_s{3600.0};
  tune::PoseTuneSettings pose_tune{};  // the sets' budgets, regions, overlap
  int map_points{5};                   // the workspace map's grid per joint (pose tune --map-points)
  // Measured against predicted at each stop: the improvement within this many points, or the damped peak
  // itself (the open one over 1 + the improvement) within peak_tolerance of the predicted (a set that takes
  // a peak down 4 times is checked on what is left of it), or within prediction_sigmas of the prediction's
  // own spread on the map (analysis::predicted_improvement: wide between measured stops, at a held-out one).
  double improvement_tolerance_points{5.0};
  double peak_tolerance{0.10};
  double prediction_sigmas{2.0};
  double held_out_freq_tolerance_pct{2.0};  // the map against a stop held out of it
  std::string command_line;
  std::string robodamp_binary;  // the emulator's executable (default: this process's)
};

// One stop: what was measured there, what the map and the chosen controller predict, what the cell did.
struct PathStop {
  std::string name;  // dwell_<k>
  std::vector<double> joints_deg;
  bool held_out{false};
  double actuator_hz{0.0};                // identified at this stop (the actuator does not move with the pose)
  std::string region;                     // the tuned set that ran there (the hand-over's hysteresis along the path)
  double gain_ns_per_m{0.0};              // its K (0: the damper off there)
  double predicted_improvement_pct{0.0};  // the driving point, the set on the mapped model (discrete loop)
  double predicted_sigma_pct{0.0};        // its one sigma from the map's spread there (points)
  double measured_improvement_pct{0.0};   // the emulator's impacts, control on against off
  double coherence_min{0.0};
  int records{0};
  bool on_cell{false};  // the verify run measured it
  // The job at its speed at this pose on the mapped model, the robot in its plane: open loop by SDM over the
  // model's modes (open_limit_mm) and over the loop's plant alone (loop_open_limit_mm, pose_schedule.modes),
  // damped by the sampled loop's SDM on that plant. Worse or not is judged against the same plant's open loop.
  double open_limit_mm{0.0}, loop_open_limit_mm{0.0}, damped_limit_mm{0.0};
  std::string limit_note;  // why the damper's effect on the cut is not claimed there, if it is not
  [[nodiscard]] bool improvement_held(double tolerance_points, double peak_tolerance, double sigmas) const;
  // The damped peak measured over the predicted one, minus one.
  [[nodiscard]] double peak_error() const {
    return (100.0 + predicted_improvement_pct) / (100.0 + measured_improvement_pct) - 1.0;
  }
  [[nodiscard]] bool cut_not_worse() const {  // kNotWorse; with the damper off the cut is the open loop's
    return gain_ns_per_m == 0.0 || damped_limit_mm >= 0.995 * loop_open_limit_mm;
  }
};

struct PathCommissionResult {
  Outcome outcome{Outcome::kFailed};
  Stage stage{Stage::kMeasure};
  std::string reason;
  std::vector<StageTime> times;
  double wall_s{0.0};
  std::vector<PathStop> stops;
  std::vector<analysis::ModeCheckRow> map_rows;  // the map at the measured and held-out stops
  double held_out_worst_freq_error_pct{0.0};
  int held_out_modes_missed{0};
  double actuator_spread_pct{0.0};  // the actuator's natural frequency over the stops
  std::string mapped_model_path;
  std::optional<tune::WorkspaceTune> tuned;
  std::string chosen;                // "robust", "scheduled" or "as given"
  std::vector<std::string> lowered;  // regions whose K was lowered: never worse than the open loop
  double job_rpm{0.0};
  std::string method;  // of the limits
  std::string trip{"none"};
  unsigned long long pose_out_of_map{0}, saturated_ticks{0};
  std::string configuration_path, report_path;
};

// Progress lines go to `progress`. Never throws for bad input: the result says the stage and the reason.
[[nodiscard]] PathCommissionResult commission_along_path(const PathCommissionSettings& s,
                                                         const std::function<void(const std::string&)>& progress);

}  // namespace robodamp::commission
