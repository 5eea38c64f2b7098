// `robodamp bench` (the main job, docs/simulation.md): the bench run on a configuration, its table, JSON and
// plots (analysis/bench_output.hpp), and what the damper does for the job's cut (milling/cut_verdict.hpp).
#include <iostream>
#include <memory>
#include <string>

#include "analysis/bench_output.hpp"
#include "analysis/loop_report.hpp"
#include "apps/cli.hpp"
#include "config/milling_config.hpp"
#include "milling/cut_verdict.hpp"
#include "milling/study_report.hpp"

namespace robodamp::apps {

namespace {

struct BenchArgs {
  std::string config_path{default_cell_config()};
  std::string job_path;  // the cut the verdict is about (default the configuration's spindle.job)
  int cut_speeds{60};
  JsonOut json;
  std::string plot_dir;
  int jobs{0};  // threads for the independent runs; 0 = one per core
};

// 0 PASS, 1 mismatch (or an output that could not be written), 3 unstable (no closed-loop tests).
int run_bench(const BenchArgs& a) {
  const analysis::Bench bench(config::load_config_file(a.config_path));
  const auto report = bench.run([](const std::string& line) { std::cerr << "[bench] " << line << std::endl; },
                                static_cast<std::size_t>(a.jobs));
  std::cout << analysis::bench_table(bench, report);
  nlohmann::json j = analysis::bench_report_json(bench, report);
  const config::Config& cfg = bench.model().config();
  const std::string job = !a.job_path.empty() ? a.job_path : cfg.spindle.job_resolved;
  if (!job.empty() && report.ran_closed_loop) {
    const milling::CutVerdict v = milling::cut_verdict(cfg, config::load_milling_config(job), a.cut_speeds);
    std::cout << "\n" << milling::cut_verdict_text(v);
    j["cut"] = milling::cut_verdict_json(v);
  } else {
    std::cout
        << "\n(no milling job: give --job, or spindle.job in the configuration, for what the damper does for a cut)\n";
  }
  std::cout << "MODEL AGREEMENT (the simulated bench against the analysis, not the cut): " << report.verdict << "\n";
  if (!emit_json(a.json, j.dump(2), "bench")) return 1;
  if (a.json.to_file()) std::cout << "wrote " << a.json.path << '\n';
  if (!a.plot_dir.empty()) {
    std::string err = analysis::plot_analysis(bench.model(), report.analysis, a.plot_dir);
    if (err.empty()) err = analysis::plot_bench(bench, report, a.plot_dir);
    if (!err.empty()) {
      std::cerr << "plot: " << err << '\n';
      return 1;
    }
    std::cout << "wrote plots in " << a.plot_dir << '\n';
  }
  if (!report.ran_closed_loop) return 3;
  return report.improvement_within_5pct && report.sweep_agrees ? 0 : 1;
}

}  // namespace

void register_bench(Registry& r) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* sub = r.add("bench", "Simulated-plant bench run: impact tests control off/on, saturation, gain sweep",
                        [a] { return run_bench(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option(
         "--job", a->job_path,
         "Milling job (config/milling/*.yaml) the verdict is about: what the damper (and its speed schedule) does "
         "for that cut; default the configuration's spindle.job")
      ->check(CLI::ExistingFile);
  r.whole_number(sub, "--cut-speeds", a->cut_speeds, {"(speeds)", 2, 5000},
                 "Speeds over the job's range the cut verdict checks");
  r.json(sub, a->json, "The report");
  r.plot_dir(sub, a->plot_dir, "the FRFs, Nyquist, gain sweep and bench plots");
  r.whole_number(sub, "--jobs", a->jobs, {"(threads)", 0, 256, false, false, "0 = one per core"},
                 "Threads for the independent runs (0 = one per core, 1 = serial); the report is the same for any");
}

}  // namespace robodamp::apps
