// `robodamp tune`: compensator synthesis (tune/compensator_search.hpp, docs/tuning.md). It searches the
// configuration's compensator (as a rational block) and gain, prints progress, compares the result with
// C1, C2 and C3 on the same chain and job, and writes the tuned configuration only when every constraint
// holds and the written file passes the configuration checks and the analysis.
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>
#include <sstream>

#include <nlohmann/json.hpp>

#include "analysis/loop_model.hpp"
#include "apps/cli.hpp"
#include "config/file_paths.hpp"
#include "apps/gnuplot.hpp"
#include "tune/tune_report.hpp"
#include "tune/compensator_search.hpp"
#include "tune/tuned_file.hpp"
#include "tune/robustness.hpp"
#include "tune/verification.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;

struct TuneArgs {
  std::string config_path{default_cell_config()};
  std::string job_path;
  std::string out_path;
  JsonOut json;
  std::string plot_dir, plot_path;
  std::vector<std::string> also_paths;  // more plants: the worst case is tuned
  std::optional<double> shift_pct;      // each plant also with its modes shifted by -/+ this
  std::string start_path;               // resume from this configuration's tuned compensator, K and polarity
  tune::TuneSettings settings;
};

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// The command that writes this file again (the options that differ from their defaults).
std::string command_line(const TuneArgs& a) {
  const tune::TuneSettings d;
  std::string c = "robodamp tune --config " + a.config_path + (a.job_path.empty() ? "" : " --job " + a.job_path);
  for (const auto& p : a.also_paths) c += " --also " + p;
  if (a.shift_pct) c += " --shift-pct " + num(*a.shift_pct);
  if (!a.start_path.empty()) c += " --start " + a.start_path;
  const tune::TuneSettings& s = a.settings;
  if (s.gain_margin_min_db != d.gain_margin_min_db) c += " --gain-margin-db " + num(s.gain_margin_min_db);
  if (s.phase_margin_min_deg != d.phase_margin_min_deg) c += " --phase-margin-deg " + num(s.phase_margin_min_deg);
  if (s.delay_margin_min_ms != d.delay_margin_min_ms) c += " --delay-margin-ms " + num(s.delay_margin_min_ms);
  if (s.impact_peak_n) c += " --impact-n " + num(*s.impact_peak_n);
  if (s.impact_duration_ms) c += " --impact-ms " + num(*s.impact_duration_ms);
  if (s.depth_at_speed_min_mm > 0.0) c += " --depth-at-speed-mm " + num(s.depth_at_speed_min_mm);
  if (s.global_evaluations != d.global_evaluations) c += " --evaluations " + std::to_string(s.global_evaluations);
  if (s.local_evaluations != d.local_evaluations) c += " --polish " + std::to_string(s.local_evaluations);
  if (s.seed != d.seed) c += " --seed " + std::to_string(s.seed);
  if (s.restarts != d.restarts) c += " --restarts " + std::to_string(s.restarts);
  if (s.no_worse_mode) c += " --no-worse-mode";
  return c + " --out " + a.out_path;
}

// The written file's header: where it comes from, the command that writes it again, and what was verified.
std::string tuned_header(const TuneArgs& a, const std::optional<tune::Verification>& v, bool scheduled) {
  std::ostringstream h;
  h << "# robodamp tune wrote this (docs/tuning.md) from " << a.config_path;
  if (!a.job_path.empty()) h << " for " << a.job_path;
  h << ":\n#   " << command_line(a) << "\n";
  if (v) {
    char b[400];
    std::snprintf(b, sizeof b,
                  "# Verified (%s, %zu speeds): damped minimum %.3f mm at %.1f rpm, %.3f mm at the job's %.1f rpm;\n"
                  "# the time-domain cut with the real Controller: %.3f mm and %.3f mm there.\n",
                  v->method.c_str(), v->damped_curve_mm.size(), v->min_depth_mm, v->min_rpm, v->depth_at_speed_mm,
                  v->speed_rpm, v->time_domain_at_min_mm, v->time_domain_at_speed_mm);
    h << b;
  }
  if (scheduled)
    h << "# " << a.config_path
      << "'s controller.speed_schedule is not kept: it chose K for the controller tuned here "
         "(robodamp schedule writes one for this file).\n";
  h << "# Everything else is " << a.config_path << "'s, whose header follows.\n#\n";
  return h.str();
}

// --start's candidate: a configuration robodamp tune wrote (its chain's rational compensator, K, polarity).
tune::Candidate start_candidate(const std::string& path) {
  const config::Config c = config::load_config_file(path);
  if (const auto start = tune::candidate_of(c)) return *start;
  throw config::ConfigError(
      {config::Problem{path,
                       {},
                       "--start",
                       "--start " + path +
                           ": its chain's compensator is not the form robodamp tune writes (model: "
                           "rational, a cubic over a cubic with every root in the left half plane); start from a "
                           "file robodamp tune wrote, or leave --start out"}});
}

// The tuned configuration written to --out, checked by parsing it and analysing its loop first.
void write_tuned(const TuneArgs& a, const config::Config& base, const tune::Candidate& candidate,
                 const std::optional<tune::Verification>& verified) {
  const config::EditedYaml edited = tune::tuned_config_text(base, candidate);
  if (!edited.comments_kept)
    std::fprintf(stderr, "tune: %s could not be edited in place; written again from its data, without its comments\n",
                 a.config_path.c_str());
  // Written beside another file than the one read: its relative file paths rebased (config/file_paths.hpp).
  const std::string text = tuned_header(a, verified, base.controller.speed_schedule.has_value()) +
                           config::rebase_file_paths(edited.text, base.source, a.out_path).text;
  const config::Config check = config::parse_config(text, a.out_path);  // throws (exit 2) before writing
  if (!analysis::LoopModel(check).stable(check.controller.gain_ns_per_m, check.controller.polarity))
    throw std::runtime_error("the written configuration's loop is not stable: nothing written");
  std::ofstream(a.out_path) << text;
  std::printf("wrote %s\n", a.out_path.c_str());
}

// The tuned file's promises verified on the job (printed and in the report): 0 to write it, else the exit code.
int report_verification(const tune::Verification& v, const TuneArgs& a, json& report) {
  std::fputs(tune::verification_report(v, report).c_str(), stdout);
  if (!emit_json(a.json, report.dump(2), "tune")) return 1;
  // The search's limit and this one are each bracketed to 0.1 %: the same within that.
  if (a.settings.depth_at_speed_min_mm > 0.0 && v.depth_at_speed_mm < a.settings.depth_at_speed_min_mm * (1.0 - 2e-3)) {
    std::cerr << "robodamp tune: the verified depth at the job's speed is below --depth-at-speed-mm: nothing written\n";
    return 3;
  }
  if (!v.time_domain_agrees()) {
    std::cerr << "robodamp tune: the time-domain cut disagrees with the " << v.method
              << " by more than 5 %: nothing written\n";
    return 3;
  }
  return 0;
}

// 0 tuned and written (or no --out), 3 no candidate met every constraint (nothing written), 2 bad input.
int run_tune(const TuneArgs& a) {
  std::optional<config::MillingConfig> job;
  if (!a.job_path.empty()) job = config::load_milling_config(a.job_path);
  std::vector<std::string> paths{a.config_path};
  paths.insert(paths.end(), a.also_paths.begin(), a.also_paths.end());
  const std::vector<tune::Evaluator> plants = tune::tuning_plants(paths, a.shift_pct, job, a.settings);
  std::vector<const tune::Evaluator*> refs;
  for (const auto& p : plants) refs.push_back(&p);
  const auto progress = [](const std::string& l) { std::cerr << l << '\n'; };
  const tune::TuneResult r = a.start_path.empty()
                                 ? tune::tune(refs, a.settings, progress)
                                 : tune::tune_from(refs, start_candidate(a.start_path), a.settings, progress);
  std::printf("robodamp tune: %s%s, %zu plant%s, %zu evaluations\n", a.config_path.c_str(),
              job ? (" on " + a.job_path).c_str() : "", plants.size(), plants.size() == 1 ? "" : "s", r.history.size());
  json report{{"config", a.config_path},
              {"also", a.also_paths},
              {"job", a.job_path},
              {"best", tune::evaluation_json_with_plants(r.best)}};
  json per_plant;
  for (std::size_t i = 0; i < plants.size(); ++i) {
    const bool nominal = !a.shift_pct || i % 3 == 0;
    const auto rows = tune::compare_designs(plants[i], plants.size() == 1 ? r.best : r.best.per_plant[i], nominal);
    std::fputs(tune::plant_report(plants[i], rows, per_plant).c_str(), stdout);
    if (const std::string plot = plot_file(a.plot_dir, a.plot_path, "tune_lobes.png"); i == 0 && !plot.empty() && job) {
      const std::string failed = tune::plot_compared_lobes(plants[i], rows, plot);
      if (!failed.empty()) throw std::runtime_error("the lobes plot: " + failed);
      std::printf("wrote %s\n", plot.c_str());
    }
  }
  report["plants"] = per_plant;
  if (plants.size() > 1) std::fputs(tune::evaluation_row("worst", r.best).c_str(), stdout);
  json history = json::array();
  for (const auto& e : r.history) history.push_back(tune::evaluation_json(e));
  report["history"] = history;
  if (!r.best.feasible()) {
    std::cerr << "robodamp tune: no candidate met every constraint; the closest violates " << r.best.binding
              << ": nothing written\n";
    if (!emit_json(a.json, report.dump(2), "tune")) return 1;
    return 3;
  }
  std::fputs(tune::robustness_report(tune::with_candidate(plants.front().base(), r.best.candidate), report).c_str(),
             stdout);
  // Every promise verified by the accurate method, and the time-domain cut with the real Controller.
  std::optional<tune::Verification> verified;
  if (job) {
    const config::Config tuned = tune::with_candidate(plants.front().base(), r.best.candidate);
    verified = tune::verify(tuned, *job);
    if (const int status = report_verification(*verified, a, report); status != 0) return status;
  } else if (!emit_json(a.json, report.dump(2), "tune")) {
    return 1;
  }
  if (!a.out_path.empty()) write_tuned(a, plants.front().base(), r.best.candidate, verified);
  return 0;
}

}  // namespace

void register_tune(Registry& r) {
  auto a = std::make_shared<TuneArgs>();
  CLI::App* sub = r.add("tune",
                        "Compensator synthesis: a rational compensator and K searched (NLopt) for the deepest damped "
                        "cut (--job) or the lowest closed-loop peak, with gain, phase and delay margins",
                        [a] { return run_tune(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--job", a->job_path, "Milling job (config/milling/*.yaml) with a damping location")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_path, "Write the tuned configuration here (only when every constraint holds)");
  r.json(sub, a->json, "The report and the search's history");
  r.number(sub, "--gain-margin-db", a->settings.gain_margin_min_db, {"dB", 0.0, 40.0}, "Smallest gain margin allowed");
  r.number(sub, "--phase-margin-deg", a->settings.phase_margin_min_deg, {"deg", 0.0, 90.0},
           "Smallest phase margin allowed");
  r.number(sub, "--delay-margin-ms", a->settings.delay_margin_min_ms, {"ms", 0.0, 1000.0, true},
           "Smallest delay margin allowed");
  r.plot_dir(sub, a->plot_dir, "with --job: tune_lobes.png, the open, C1, C2, C3 and tuned lobes of --config's plant,");
  r.deprecated(sub->add_option("--plot", a->plot_path, "With --job: write the lobes to this file (PNG)"),
               "--plot-dir DIR");
  sub->add_option(
         "--also", a->also_paths,
         "More configurations (another mounting, another pose's modes) with the same chain: the worst case over "
         "all is tuned; --out writes --config's file")
      ->check(CLI::ExistingFile);
  r.number(sub, "--shift-pct", a->shift_pct, {"%", 0.0, 50.0, true},
           "Also tune for every plant with all its modal frequencies shifted down and up by this");
  sub->add_option(
         "--start", a->start_path,
         "Resume from this configuration's tuned compensator, K and polarity (a file robodamp tune wrote): the "
         "search at its polarity from it, never worse than it")
      ->check(CLI::ExistingFile);
  r.number(sub, "--impact-n", a->settings.impact_peak_n, {"N", 0.0, 100000.0},
           "The impact (half-sine at every location) the actuator's limits must hold for; default the configuration's "
           "bench.impact_peak_n, 0 = no such constraint");
  r.number(sub, "--impact-ms", a->settings.impact_duration_ms, {"ms", 0.0, 1000.0, true},
           "Its duration; default bench.impact_duration_ms");
  r.number(sub, "--depth-at-speed-mm", a->settings.depth_at_speed_min_mm, {"mm", 0.0, 1000.0},
           "With --job: the damped limit at the job's spindle speed at least this (0 = free)");
  r.whole_number(sub, "--evaluations", a->settings.global_evaluations, {"(evaluations per polarity)", 10, 100000},
                 "Global search budget per polarity");
  r.whole_number(sub, "--polish", a->settings.local_evaluations, {"(evaluations per polarity)", 0, 100000},
                 "Local polish budget per polarity");
  r.whole_number(sub, "--seed", a->settings.seed, {"(seed)", 0, 999999}, "The global search's seed");
  r.whole_number(sub, "--restarts", a->settings.restarts, {"(searches)", 1, 100},
                 "Whole searches with seeds --seed, --seed + 1, ...; the best is kept");
  sub->add_flag(
      "--no-worse-mode", a->settings.no_worse_mode,
      "A constraint: no robot mode's receptance peak (first FRF, within +-10 %) worse than open loop on any plant");
}

}  // namespace robodamp::apps
