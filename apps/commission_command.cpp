// `robodamp commission`: measure, identify, tune, verify on the cell, write (commission/commission.hpp,
// docs/identification.md "Commissioning in one command").
#include <cstdio>
#include <iostream>
#include <memory>

#include <spdlog/spdlog.h>

#include "apps/cli.hpp"
#include "commission/commission.hpp"

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
};

std::string command_line(const CommissionArgs& a) {
  std::string c = "robodamp commission --config " + a.config_path + " --job " + a.job_path + " --out " + a.out_dir;
  const tune::TuneSettings d = commission::CommissionSettings{}.tune;
  const tune::TuneSettings& s = a.settings.tune;
  char b[64];
  if (a.shift_pct) std::snprintf(b, sizeof b, " --shift-pct %g", *a.shift_pct), c += b;
  if (s.global_evaluations != d.global_evaluations) c += " --evaluations " + std::to_string(s.global_evaluations);
  if (s.local_evaluations != d.local_evaluations) c += " --polish " + std::to_string(s.local_evaluations);
  if (s.seed != d.seed) c += " --seed " + std::to_string(s.seed);
  const commission::CommissionSettings ds;
  if (a.settings.schedule_speeds != ds.schedule_speeds) c += " --schedule-speeds " + std::to_string(a.settings.schedule_speeds);
  if (a.settings.schedule_gains != ds.schedule_gains) c += " --schedule-gains " + std::to_string(a.settings.schedule_gains);
  for (const auto& t : a.settings.tap_tests) c += " --tap-tests " + t;
  return c;
}

int run_commission(CommissionArgs& a) {
  if (a.dry_run) {
    commission::MeasureOptions o;
    o.impacts = a.settings.tap_tests.empty();
    std::cout << "robodamp commission --dry-run: stage 1, measure:\n" << commission::measurement_plan(a.config_path, o);
    std::cout << (o.impacts ? "Stage 4, verify: the impacts again with the tuned controller, then the regenerative cuts "
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
  try {
    s.from = commission::stage_from_string(a.from);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp commission: " << e.what() << '\n';
    return 2;
  }
  s.command_line = command_line(a);
  const commission::CommissionResult r = commission::commission(s, [](const std::string& l) { spdlog::info("{}", l); });
  if (r.outcome == commission::Outcome::kVerified) {
    std::printf("robodamp commission: VERIFIED in %.1f s: wrote %s\n", r.wall_s, r.configuration_path.c_str());
  } else {
    std::fprintf(stderr, "robodamp commission: stopped at the %s stage after %.1f s: %s; no configuration written\n",
                 commission::to_string(r.stage), r.wall_s, r.reason.c_str());
  }
  if (!r.report_path.empty()) std::printf("robodamp commission: the report is %s\n", r.report_path.c_str());
  return commission::exit_code(r.outcome);
}

}  // namespace

void register_commission(Registry& r) {
  auto a = std::make_shared<CommissionArgs>();
  CLI::App* sub = r.add("commission",
                        "Commission a cell in one command: measure, identify, tune for the job (robust over the fit's "
                        "uncertainty), verify on the cell, write DIR/configuration.yaml and DIR/report.html",
                        [a] { return run_commission(*a); });
  sub->add_option("--config", a->config_path, "The cell's configuration (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--job", a->job_path, "Milling job (config/milling/*.yaml) whose structure is the cell's damping location")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for every stage's output, configuration.yaml and report.html")->required();
  sub->add_option("--from", a->from, "Start at this stage, reusing the earlier stages' output in --out: measure, "
                                     "identify, tune or verify");
  r.number(sub, "--shift-pct", a->shift_pct, {"%", 0.0, 50.0, true},
           "Tune robust over the identified modes shifted by -/+ this (default: 3 x their spread over the FRFs, 1-10 %)");
  r.whole_number(sub, "--evaluations", a->settings.tune.global_evaluations, {"(evaluations per polarity)", 10, 100000},
                 "Global search budget per polarity");
  r.whole_number(sub, "--polish", a->settings.tune.local_evaluations, {"(evaluations per polarity)", 0, 100000},
                 "Local polish budget per polarity");
  r.whole_number(sub, "--cut-revs", a->settings.cut_revolutions, {"(revolutions)", 60, 100000},
                 "Revolutions of each regenerative cut in the HIL emulator's check (a cell behind can.interface unix:...)");
  r.whole_number(sub, "--seed", a->settings.tune.seed, {"(seed)", 0, 999999}, "The global search's seed");
  r.whole_number(sub, "--schedule-speeds", a->settings.schedule_speeds, {"(speeds)", 2, 5000},
                 "Grid speeds of the speed schedule over the job's range (checks are added between)");
  r.whole_number(sub, "--schedule-gains", a->settings.schedule_gains, {"(gains per controller)", 1, 24},
                 "Gains the speed schedule tries per controller");
  sub->add_option("--operator", a->settings.operator_name, "Who commissions (the report; default the login name)");
  sub->add_option("--tap-tests", a->settings.tap_tests,
                  "A real cell: your modal kit's tap tests between the cell's locations (universal files, nodes = the "
                  "configuration's location ids, or frf_<response>_<excitation>.csv); robodamp then measures with the "
                  "actuator's chirp only, orders no hammer blow and no cut, and verifies with the chirp, control off and on")
      ->check(CLI::ExistingFile);
  r.number(sub, "--tap-tolerance-pct", a->settings.tap_tolerance_pct, {"%", 0.1, 20.0},
           "How far a tapped mode may sit from the same mode in the actuator's chirp");
  sub->add_flag("--dry-run", a->dry_run, "Print what would run on the cell (levels, durations, what moves) and stop");
}

}  // namespace robodamp::apps
