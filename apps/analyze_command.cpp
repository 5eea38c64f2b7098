// `robodamp analyze`: stability, margins, the gain limit, the polarity and the predicted improvement of
// the damping loop (analysis/loop_report.hpp), with the harmonic notches' speed map, the pose schedule, the
// speed schedule (analysis/schedule_report.hpp), robustness (tune/tune_report.hpp) and the job's limits at a
// spindle speed (milling/study_report.hpp), as a table, JSON and plots.
#include <memory>
#include <optional>
#include <string>

#include "analysis/loop_report.hpp"
#include "analysis/schedule_report.hpp"
#include "apps/cli.hpp"
#include "milling/study_report.hpp"
#include "tune/tune_report.hpp"

namespace robodamp::apps {

namespace {

struct AnalyzeArgs {
  std::string config_path{default_cell_config()};
  JsonOut json;
  std::string plot_dir;
  std::optional<double> spindle_rpm;
  bool spindle_sweep{false};
  bool base{false};
  std::string job_path;  // the cut the verdict is about (default spindle.job)
  int cut_speeds{60};
};

// 0 stable, 3 unstable at the configured K, 1 plot failed.
int run_analyze(const AnalyzeArgs& a) {
  if (a.spindle_sweep) {
    const analysis::TextReport r = analysis::notch_speed_map_report(config::load_config_file(a.config_path));
    return print_report(r.json.dump(2), a.json, "analyze", r.text, "", {}, "");
  }
  if (const config::Config cfg = config::load_config_file(a.config_path); cfg.pose_schedule && !a.base) {
    const analysis::TextReport r = analysis::pose_schedule_report(cfg);
    return print_report(r.json.dump(2), a.json, "analyze", r.text, "", {}, "");
  }
  const analysis::LoopModel model(config::load_config_file(a.config_path), a.spindle_rpm);
  const auto result = analysis::analyse(model);
  auto report = analysis::analysis_report(model, result);
  if (a.spindle_rpm && !model.config().spindle.job_resolved.empty())
    report["job_limits"] = milling::job_limits_json(model.config(), *a.spindle_rpm);
  std::string table = analysis::analysis_table(report) +
                      (result.stable ? tune::robustness_section(model.config(), report) : std::string()) +
                      analysis::speed_schedule_section(model.config(), report);
  const std::string job = !a.job_path.empty() ? a.job_path : model.config().spindle.job_resolved;
  if (!job.empty() && result.stable) {
    const milling::CutVerdict v = milling::cut_verdict(model.config(), config::load_milling_config(job), a.cut_speeds);
    table += milling::cut_verdict_text(v);
    report["cut"] = milling::cut_verdict_json(v);
  }
  if (print_report(
          report.dump(2), a.json, "analyze", table, a.plot_dir,
          [&] { return analysis::plot_analysis(model, result, a.plot_dir); },
          "frf_open_closed.png, nyquist.png, gain_sweep.png in " + a.plot_dir) != 0)
    return 1;
  return result.stable ? 0 : 3;
}

}  // namespace

void register_analyze(Registry& r) {
  auto a = std::make_shared<AnalyzeArgs>();
  CLI::App* sub = r.add("analyze", "Closed-loop stability, margins, polarity and predicted improvement",
                        [a] { return run_analyze(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option(
         "--job", a->job_path,
         "Milling job (config/milling/*.yaml): what the damper (and its speed schedule) does for that cut, by the "
         "accurate method; default the configuration's spindle.job")
      ->check(CLI::ExistingFile);
  r.whole_number(sub, "--cut-speeds", a->cut_speeds, {"(speeds)", 2, 5000},
                 "Speeds over the job's range the cut verdict checks");
  r.json(sub, a->json, "The analysis (or the pose schedule's regions, or the --spindle-sweep map)");
  r.plot_dir(sub, a->plot_dir, "frf_open_closed.png, nyquist.png and gain_sweep.png");
  r.number(sub, "--spindle-rpm", a->spindle_rpm, {"rpm", 0.0, 200000.0},
           "Analyse with controller.harmonic_notch at this spindle speed (spindle.teeth)");
  sub->add_flag("--spindle-sweep", a->spindle_sweep,
                "The harmonic notches across the spindle's speed range: refused speeds and their cost at each mode");
  sub->add_flag("--no-pose-schedule", a->base,
                "With pose_schedule: analyse the configuration's own robot section instead of each region's set");
}

}  // namespace robodamp::apps
