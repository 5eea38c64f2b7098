// `robodamp tune`: compensator synthesis (tune/compensator_search.hpp, docs/tuning.md). It searches the
// configuration's compensator (as a rational block) and gain, prints progress, compares the result with
// C1, C2 and C3 on the same chain and job, and writes the tuned configuration only when every constraint
// holds and the written file passes the configuration checks and the analysis.
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "tune/tune_report.hpp"
#include "tune/compensator_search.hpp"
#include "tune/tuned_file.hpp"
#include "tune/verification.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;

struct TuneArgs {
  TuneArgs() { cmd.config_path = default_cell_config(); }
  tune::TuneCommand cmd;
  JsonOut json;
  std::string plot_dir, plot_path;
};

// The tuned configuration written to --out, checked by parsing it and analysing its loop first.
void write_tuned(const TuneArgs& a, const config::Config& base, const tune::Candidate& candidate,
                 const std::optional<tune::Verification>& verified) {
  bool comments_kept = true;
  const std::string text = tune::tuned_file_text(a.cmd, base, candidate, verified, comments_kept);
  if (!comments_kept)
    std::fprintf(stderr, "tune: %s could not be edited in place; written again from its data, without its comments\n",
                 a.cmd.config_path.c_str());
  std::ofstream(a.cmd.out_path) << text;
  std::printf("wrote %s\n", a.cmd.out_path.c_str());
}

// The tuned file's promises verified on the job (printed and in the report): 0 to write it, else the exit code.
int report_verification(const tune::Verification& v, const TuneArgs& a, json& report) {
  std::fputs(tune::verification_report(v, report).c_str(), stdout);
  if (!emit_json(a.json, report.dump(2), "tune")) return 1;
  // The search's limit and this one are each bracketed to 0.1 %: the same within that.
  if (a.cmd.settings.depth_at_speed_min_mm > 0.0 &&
      v.depth_at_speed_mm < a.cmd.settings.depth_at_speed_min_mm * (1.0 - 2e-3)) {
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
  if (!a.cmd.job_path.empty()) job = config::load_milling_config(a.cmd.job_path);
  std::vector<std::string> paths{a.cmd.config_path};
  paths.insert(paths.end(), a.cmd.also_paths.begin(), a.cmd.also_paths.end());
  const std::vector<tune::Evaluator> plants = tune::tuning_plants(paths, a.cmd.shift_pct, job, a.cmd.settings);
  std::vector<const tune::Evaluator*> refs;
  for (const auto& p : plants) refs.push_back(&p);
  const auto progress = [](const std::string& l) { std::cerr << l << '\n'; };
  const tune::TuneResult r = a.cmd.start_path.empty() ? tune::tune(refs, a.cmd.settings, progress)
                                                      : tune::tune_from(refs, tune::start_candidate(a.cmd.start_path),
                                                                        a.cmd.settings, progress);
  std::printf("robodamp tune: %s%s, %zu plant%s, %zu evaluations\n", a.cmd.config_path.c_str(),
              job ? (" on " + a.cmd.job_path).c_str() : "", plants.size(), plants.size() == 1 ? "" : "s",
              r.history.size());
  json report = tune::search_report(a.cmd, plants, r, job.has_value(),
                                    plot_file(a.plot_dir, a.plot_path, "tune_lobes.png"), stdout);
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
  if (!a.cmd.out_path.empty()) write_tuned(a, plants.front().base(), r.best.candidate, verified);
  return 0;
}

}  // namespace

void register_tune(Registry& r) {
  auto a = std::make_shared<TuneArgs>();
  CLI::App* sub = r.add("tune",
                        "Compensator synthesis: a rational compensator and K searched (NLopt) for the deepest damped "
                        "cut (--job) or the lowest closed-loop peak, with gain, phase and delay margins",
                        [a] { return run_tune(*a); });
  sub->add_option("--config", a->cmd.config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--job", a->cmd.job_path, "Milling job (config/milling/*.yaml) with a damping location")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", a->cmd.out_path, "Write the tuned configuration here (only when every constraint holds)");
  r.json(sub, a->json, "The report and the search's history");
  r.number(sub, "--gain-margin-db", a->cmd.settings.gain_margin_min_db, {"dB", 0.0, 40.0},
           "Smallest gain margin allowed");
  r.number(sub, "--phase-margin-deg", a->cmd.settings.phase_margin_min_deg, {"deg", 0.0, 90.0},
           "Smallest phase margin allowed");
  r.number(sub, "--delay-margin-ms", a->cmd.settings.delay_margin_min_ms, {"ms", 0.0, 1000.0, true},
           "Smallest delay margin allowed");
  r.plot_dir(sub, a->plot_dir, "with --job: tune_lobes.png, the open, C1, C2, C3 and tuned lobes of --config's plant,");
  r.deprecated(sub->add_option("--plot", a->plot_path, "With --job: write the lobes to this file (PNG)"),
               "--plot-dir DIR");
  sub->add_option(
         "--also", a->cmd.also_paths,
         "More configurations (another mounting, another pose's modes) with the same chain: the worst case over "
         "all is tuned; --out writes --config's file")
      ->check(CLI::ExistingFile);
  r.number(sub, "--shift-pct", a->cmd.shift_pct, {"%", 0.0, 50.0, true},
           "Also tune for every plant with all its modal frequencies shifted down and up by this");
  sub->add_option(
         "--start", a->cmd.start_path,
         "Resume from this configuration's tuned compensator, K and polarity (a file robodamp tune wrote): the "
         "search at its polarity from it, never worse than it")
      ->check(CLI::ExistingFile);
  r.number(sub, "--impact-n", a->cmd.settings.impact_peak_n, {"N", 0.0, 100000.0},
           "The impact (half-sine at every location) the actuator's limits must hold for; default the configuration's "
           "bench.impact_peak_n, 0 = no such constraint");
  r.number(sub, "--impact-ms", a->cmd.settings.impact_duration_ms, {"ms", 0.0, 1000.0, true},
           "Its duration; default bench.impact_duration_ms");
  r.number(sub, "--depth-at-speed-mm", a->cmd.settings.depth_at_speed_min_mm, {"mm", 0.0, 1000.0},
           "With --job: the damped limit at the job's spindle speed at least this (0 = free)");
  r.whole_number(sub, "--evaluations", a->cmd.settings.global_evaluations, {"(evaluations per polarity)", 10, 100000},
                 "Global search budget per polarity");
  r.whole_number(sub, "--polish", a->cmd.settings.local_evaluations, {"(evaluations per polarity)", 0, 100000},
                 "Local polish budget per polarity");
  r.whole_number(sub, "--seed", a->cmd.settings.seed, {"(seed)", 0, 999999}, "The global search's seed");
  r.whole_number(sub, "--restarts", a->cmd.settings.restarts, {"(searches)", 1, 100},
                 "Whole searches with seeds --seed, --seed + 1, ...; the best is kept");
  sub->add_flag(
      "--no-worse-mode", a->cmd.settings.no_worse_mode,
      "A constraint: no robot mode's receptance peak (first FRF, within +-10 %) worse than open loop on any plant");
}

}  // namespace robodamp::apps
