// `robodamp commission`: measure, identify, tune, verify on the cell, write (commission/commission.hpp,
// docs/identification.md "Commissioning in one command").
#include <cstdio>
#include <iostream>
#include <memory>

#include <spdlog/spdlog.h>

#include "apps/cli.hpp"
#include "commission/command_line.hpp"

namespace robodamp::apps {

namespace {

struct CommissionArgs {
  std::string config_path{default_cell_config()};
  std::string job_path;
  std::string out_dir;
  std::string from{"measure"};
  std::optional<double> shift_pct;
  bool dry_run{false};
  commission::CommissionSettings settings;
  // Along the robot's path (commission/path_commission.hpp).
  bool along_path{false};
  commission::PathCommissionSettings path;
  bool evaluations_given{false}, polish_given{false};
  double peak_tolerance_pct{10.0};
};

bool stage_from(const std::string& text, commission::Stage& out) {
  try {
    out = commission::stage_from_string(text);
    return true;
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp commission: " << e.what() << '\n';
    return false;
  }
}

// The verdict line, the report's path and the exit status of either commissioning.
template <class Result>
int finish(const Result& r, const std::string& where) {
  if (r.outcome == commission::Outcome::kVerified)
    std::printf("robodamp commission: VERIFIED%s in %.1f s: wrote %s\n", where.c_str(), r.wall_s,
                r.configuration_path.c_str());
  else
    std::fprintf(stderr, "robodamp commission: stopped at the %s stage after %.1f s: %s; no configuration written\n",
                 commission::to_string(r.stage), r.wall_s, r.reason.c_str());
  if (!r.report_path.empty()) std::printf("robodamp commission: the report is %s\n", r.report_path.c_str());
  return commission::exit_code(r.outcome);
}

int run_along_path(const CommissionArgs& a) {
  commission::PathCommissionSettings s = a.path;
  s.config_path = a.config_path;
  s.job_path = a.job_path;
  s.out_dir = a.out_dir;
  s.peak_tolerance = a.peak_tolerance_pct / 100.0;
  if (!stage_from(a.from, s.from)) return 2;
  // The pose tune's own budgets (60 / 30 a set) unless given: a schedule tunes a set per region.
  s.pose_tune.tune.global_evaluations = a.evaluations_given ? a.settings.tune.global_evaluations : 60;
  s.pose_tune.tune.local_evaluations = a.polish_given ? a.settings.tune.local_evaluations : 30;
  s.pose_tune.tune.seed = a.settings.tune.seed;
  s.command_line = commission::command_line(s);
  const commission::PathCommissionResult r =
      commission::commission_along_path(s, [](const std::string& l) { spdlog::info("{}", l); });
  return finish(r, " along the path at " + std::to_string(r.stops.size()) + " stops");
}

int run_commission(CommissionArgs& a) {
  if (a.along_path) {
    if (a.dry_run || !a.settings.tap_tests.empty() || a.shift_pct) {
      std::cerr << "robodamp commission: --along-path takes none of --dry-run, --tap-tests, --shift-pct (the stops are "
                   "measured by robodamp's hammer in the HIL emulator, and the tune is robust over the map's poses)\n";
      return 2;
    }
    return run_along_path(a);
  }
  if (!a.path.trajectory.empty() || !a.path.hold_out.empty()) {
    std::cerr << "robodamp commission: --pose-at and --hold-out belong to --along-path\n";
    return 2;
  }
  if (a.dry_run) {
    commission::MeasureOptions o;
    o.impacts = a.settings.tap_tests.empty();
    std::cout << "robodamp commission --dry-run: stage 1, measure:\n" << commission::measurement_plan(a.config_path, o);
    std::cout << (o.impacts
                      ? "Stage 4, verify: the impacts again with the tuned controller, then the regenerative cuts "
                        "(through the emulator) or the damped cut in time (the simulated plant).\n"
                      : "Stage 4, verify: the same chirp with the tuned controller running (control ON), no hammer, "
                        "no cut.\n");
    return 0;
  }
  commission::CommissionSettings s = a.settings;
  s.config_path = a.config_path;
  s.job_path = a.job_path;
  s.out_dir = a.out_dir;
  s.shift_pct = a.shift_pct;
  if (!stage_from(a.from, s.from)) return 2;
  s.command_line = commission::command_line(s);
  const commission::CommissionResult r = commission::commission(s, [](const std::string& l) { spdlog::info("{}", l); });
  return finish(r, "");
}

}  // namespace

void register_commission(Registry& r) {
  auto a = std::make_shared<CommissionArgs>();
  CLI::App* sub = r.add("commission",
                        "Commission a cell in one command: measure, identify, tune for the job (robust over the fit's "
                        "uncertainty), verify on the cell, write DIR/configuration.yaml and DIR/report.html",
                        [a] { return run_commission(*a); });
  sub->add_option("--config", a->config_path, "The cell's configuration (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--job", a->job_path,
                  "Milling job (config/milling/*.yaml) whose structure is the cell's damping location")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for every stage's output, configuration.yaml and report.html")
      ->required();
  sub->add_option("--from", a->from,
                  "Start at this stage, reusing the earlier stages' output in --out: measure, "
                  "identify, tune or verify");
  r.number(
      sub, "--shift-pct", a->shift_pct, {"%", 0.0, 50.0, true},
      "Tune robust over the identified modes shifted by -/+ this (default: 3 x their spread over the FRFs, 1-10 %)");
  r.whole_number(sub, "--evaluations", a->settings.tune.global_evaluations, {"(evaluations per polarity)", 10, 100000},
                 "Global search budget per polarity");
  r.whole_number(sub, "--polish", a->settings.tune.local_evaluations, {"(evaluations per polarity)", 0, 100000},
                 "Local polish budget per polarity");
  r.whole_number(
      sub, "--cut-revs", a->settings.cut_revolutions, {"(revolutions)", 60, 100000},
      "Revolutions of each regenerative cut in the HIL emulator's check (a cell behind can.interface unix:...)");
  r.whole_number(sub, "--seed", a->settings.tune.seed, {"(seed)", 0, 999999}, "The global search's seed");
  r.whole_number(sub, "--schedule-speeds", a->settings.schedule_speeds, {"(speeds)", 2, 5000},
                 "Grid speeds of the speed schedule over the job's range (checks are added between)");
  r.whole_number(sub, "--schedule-gains", a->settings.schedule_gains, {"(gains per controller)", 1, 24},
                 "Gains the speed schedule tries per controller");
  sub->add_option("--operator", a->settings.operator_name, "Who commissions (the report; default the login name)");
  sub->add_option(
         "--tap-tests", a->settings.tap_tests,
         "A real cell: your modal kit's tap tests between the cell's locations (universal files, nodes = the "
         "configuration's location ids, or frf_<response>_<excitation>.csv); robodamp then measures with the "
         "actuator's chirp only, orders no hammer blow and no cut, and verifies with the chirp, control off and on")
      ->check(CLI::ExistingFile);
  r.number(sub, "--tap-tolerance-pct", a->settings.tap_tolerance_pct, {"%", 0.1, 20.0},
           "How far a tapped mode may sit from the same mode in the actuator's chirp");
  sub->add_flag("--dry-run", a->dry_run, "Print what would run on the cell (levels, durations, what moves) and stop");
  sub->add_flag(
      "--along-path", a->along_path,
      "Commission a pose-scheduled cell along the robot's path (docs/pose_dynamics.md): measure at each stop the "
      "robot makes, map the modes between the stops, tune the pose schedule on the map, verify it along the same "
      "path; through the HIL emulator");
  r.whole_number(sub, "--dwells", a->path.dwells, {"(stops)", 1, 1000}, "--along-path: the stops to measure");
  sub->add_option(
      "--pose-at", a->path.trajectory,
      "--along-path: the robot's path in the HIL emulator, waypoints T:Q1,Q2,... (s and deg, as robodamp plant "
      "takes them); a stop is two waypoints at one pose");
  sub->add_option("--hold-out", a->path.hold_out,
                  "--along-path: stops (dwell_<k>) kept out of the map and checked against it");
  r.whole_number(sub, "--map-points", a->path.map_points, {"(points per joint)", 2, 41},
                 "--along-path: the workspace map's grid along the joints that move the dominant mode");
  r.whole_number(sub, "--max-regions", a->path.pose_tune.max_regions, {"(regions)", 1, 16},
                 "--along-path: the scheduled controller's regions at most");
  r.number(sub, "--improvement-tolerance", a->path.improvement_tolerance_points, {"points", 0.5, 50.0},
           "--along-path: the improvement measured at a stop against the map's prediction there");
  r.number(
      sub, "--peak-tolerance-pct", a->peak_tolerance_pct, {"%", 1.0, 100.0},
      "--along-path: ... or the damped peak measured at a stop against the predicted one (a set that takes a peak down "
      "several times is checked on what is left of it)");
  r.number(sub, "--prediction-sigmas", a->path.prediction_sigmas, {"sigma", 0.0, 5.0},
           "--along-path: ... or within this many of the prediction's one sigma from the map's spread at the stop "
           "(0: never)");
  sub->get_option("--evaluations")->each([a](const std::string&) { a->evaluations_given = true; });
  sub->get_option("--polish")->each([a](const std::string&) { a->polish_given = true; });
}

}  // namespace robodamp::apps
