// `robodamp commission` (docs/identification.md, "Commissioning in one command"): from a cell nobody has
// tuned to a verified configuration, the way a machine-tool control's servo auto-tuning does it:
//   1 measure   control off: the actuator chirp and hammer impacts (commission/measurement.hpp)
//   2 identify  the modes per FRF, the actuator's Eq. 3, a matched configuration (identify/commissioning.hpp)
//   3 tune      a compensator and gain for the job, robust over the identified modes shifted by the
//               uncertainty the fits allow (tune/compensator_search.hpp), its promises verified on the
//               identified model by the accurate method and the time-domain cut (tune/verification.hpp)
//   4 verify    on the cell: impact tests with the tuned controller running, measured against predicted
//               improvement, and the damped cut's critical depth in time against the promise
//               (commission/cell_check.hpp)
//   5 write     DIR/configuration.yaml only when every check held; DIR/report.html always.
// Each stage's output is kept in DIR; --from STAGE reuses the earlier ones. Off the real-time path.
//
// A real cell (tap_tests given; the only way on a CAN bus, and the HIL emulator told it is real): robodamp
// orders no hammer blow and no cut. measure is the actuator's chirp alone (commission/measurement.hpp, its
// readiness, rest, saturation and abort watch); identify takes the tool tip's and the other FRFs from the
// user's tap tests and checks them against the chirp (identify/tap_tests.hpp: refused when they
// contradict it); verify runs the chirp again with the tuned controller and checks the improvement at the
// actuator and the loop gain against the analysis (commission/real_cell_check.hpp); the damped depths stay
// the model's promise, checked by the accurate method and the time-domain cut on the identified model.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "commission/cell_check.hpp"
#include "commission/real_cell_check.hpp"
#include "identify/commissioning.hpp"
#include "identify/tap_tests.hpp"
#include "tune/compensator_search.hpp"
#include "tune/robustness.hpp"
#include "tune/scheduled_cut.hpp"
#include "tune/speed_schedule.hpp"
#include "tune/verification.hpp"

namespace robodamp::commission {

enum class Stage { kMeasure = 1, kIdentify, kTune, kVerify, kWrite };
[[nodiscard]] const char* to_string(Stage s);
// "measure", "identify", "tune", "verify"; throws std::invalid_argument naming the allowed ones.
[[nodiscard]] Stage stage_from_string(const std::string& s);

// The tuner's budget for commissioning: smaller than `robodamp tune`'s, for a commissioning in minutes.
[[nodiscard]] inline tune::TuneSettings commission_tune_defaults() {
  tune::TuneSettings t;
  t.global_evaluations = 200;
  t.local_evaluations = 60;
  return t;
}

struct CommissionSettings {
  std::string config_path;  // the cell
  std::string job_path;
  std::string out_dir;
  Stage from{Stage::kMeasure};
  std::optional<double> shift_pct;  // default: from the fits' spread (min_shift_pct .. max_shift_pct)
  double min_shift_pct{1.0};
  double max_shift_pct{10.0};
  tune::TuneSettings tune{commission_tune_defaults()};
  std::string command_line;     // how it was called, for the files' headers and the report
  std::string robodamp_binary;  // the emulator's executable for a HIL cell (default: this process's)
  int cut_revolutions{300};     // each regenerative cut in the HIL emulator's check
  // The speed schedule over the job's range (tune/speed_schedule.hpp): grid speeds and gains per controller.
  int schedule_speeds{80};
  int schedule_gains{4};
  std::string operator_name;  // who commissioned (the report; default the login name)
  // A real cell: the integrator's tap tests (UFF or robodamp FRF CSVs) in place of robodamp's hammer.
  std::vector<std::string> tap_tests;
  double tap_tolerance_pct{2.0};  // a tapped mode against the chirp's
};

// kRefused: the cell was not ready or at rest, or the excitation saturated; kAborted: the operator stopped it.
enum class Outcome { kVerified, kBadInput, kNotVerified, kTripped, kFailed, kRefused, kAborted };

struct StageTime {
  Stage stage;
  double wall_s{0.0};
  bool reused{false};
};

struct CommissionResult {
  Outcome outcome{Outcome::kFailed};
  Stage stage{Stage::kMeasure};  // where it stopped (kWrite when verified)
  std::string reason;            // why it stopped, empty when verified
  std::vector<StageTime> times;
  double wall_s{0.0};
  // What each stage produced (empty before it ran).
  std::optional<identify::CommissioningResult> identified;
  double shift_pct{0.0};
  std::string shift_reason;
  std::optional<tune::Evaluation> tuned;          // worst case over the plants
  std::optional<tune::Evaluation> tuned_nominal;  // on the identified plant
  std::optional<config::Config> tuned_config;
  std::optional<tune::Robustness> robustness;  // the tuned loop on the identified plant, modes shifted
  std::optional<tune::Verification> promise;
  std::optional<CellCheck> cell;
  // A real cell: the tap tests against the chirp, and the verification by the actuator's chirp.
  bool real_cell{false};
  std::optional<identify::TapTestConsistency> tap_check;
  std::optional<RealCellCheck> real_check;
  std::vector<std::pair<double, double>> open_curve_mm;  // the identified plant's open-loop lobes (SDM)
  // The speed schedule made after the tune (the tuned controller, C1 and C2 drawn in the identified chain) and
  // its check in time with the real supervisor on the identified model; the configuration it is written in.
  std::optional<tune::SpeedSchedule> schedule;
  std::optional<tune::ScheduledCut> schedule_in_time;
  std::optional<config::Config> scheduled_config;
  std::string configuration_path;  // written when verified
  std::string report_path;
};

// Progress lines (stage, time, numbers) go to `progress`. Never throws for bad input: the result says the
// stage and the reason.
[[nodiscard]] CommissionResult commission(const CommissionSettings& s,
                                          const std::function<void(const std::string&)>& progress);

// 0 verified, 2 bad input, 3 not verified, 4 the loop tripped while measuring, 6 refused (not ready, not at
// rest, the excitation saturated), 8 aborted by the operator, 1 otherwise.
[[nodiscard]] int exit_code(Outcome o);

// The shift of the modal frequencies the identified fits allow: 3 x the largest relative spread of one
// mode's frequency over the FRFs that show it, within [min_pct, max_pct]; the reason says which mode.
[[nodiscard]] std::pair<double, std::string> modal_uncertainty_pct(const identify::CommissioningResult& r,
                                                                   double min_pct, double max_pct);

}  // namespace robodamp::commission
