// `robodamp cut`: one simulated cut of a milling job in time, with the chatter detector's verdict, the
// forces, the machined wall and plots; or, with --critical, the time-domain critical depth at speeds next
// to the zero-order limit (docs/milling.md, "Time domain").
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "milling/cut_report.hpp"
#include "milling/study_report.hpp"
#include "commission/hil_critical.hpp"
#include "milling/cut_job.hpp"

namespace robodamp::apps {

using nlohmann::json;

namespace {

struct CutArgs {
  std::string job_path{default_job()};  // --job (the deprecated --config)
  std::string structure;
  std::optional<double> axial_mm, radial_mm;
  std::vector<double> rpm;
  std::optional<int> revs;
  bool critical{false};
  bool damped{false};
  JsonOut json;
  std::string plot_dir;
  std::string controller_path;   // replaces every controller part's damping configuration
  std::vector<double> pose_deg;  // the joints of the job's robot pose parts
  std::string hil_path;          // --critical through the HIL emulator too: the cell's configuration
};

// One cut at one speed (no --critical): its verdict, the damper's limits, the plots.
std::optional<int> one_cut(const CutArgs& a, const config::MillingConfig& cfg, const milling::Structure& structure,
                           milling::CutOverrides ov, const std::vector<double>& speeds, json& out) {
  if (speeds.size() > 1)
    throw config::ConfigError(
        {config::Problem{cfg.source, {}, "--rpm", "--rpm: one speed for a cut (several with --critical)"}});
  if (!a.rpm.empty()) ov.rpm = speeds.front();
  const milling::CutJob job = milling::make_cut_job(cfg, structure, ov);
  const auto t0 = std::chrono::steady_clock::now();
  const milling::CutOutcome o = milling::run_job(job);
  out = milling::cut_json(job, o, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  std::fputs(milling::cut_lines(job, o, out).c_str(), stdout);
  if (!a.plot_dir.empty()) {
    if (auto e = milling::plot_cut(o, a.plot_dir); !e.empty()) {
      std::cerr << "plot: " << e << '\n';
      return 1;
    }
    std::printf("wrote plots in %s\n", a.plot_dir.c_str());
  }
  return std::nullopt;
}

// The job with the options applied and checked, then one cut or the critical-depth study.
int run_cut(const CutArgs& a) {
  try {
    config::MillingConfig cfg = config::load_milling_config(a.job_path);
    milling::apply_pose(cfg, a.pose_deg);
    if (!a.hil_path.empty() &&
        (!a.critical || !a.structure.empty() || !a.controller_path.empty() || !a.pose_deg.empty()))
      throw config::ConfigError(
          {config::Problem{cfg.source,
                           {},
                           "--hil",
                           "--hil goes with --critical and the job's own structure (no --structure, "
                           "--controller or --pose): the emulator cuts the job as its file says"}});
    const config::StructureConfig chosen = milling::selected_structure(cfg, a.structure, a.controller_path);
    const milling::Structure structure(chosen, false);
    const milling::CutOverrides ov{std::nullopt, a.axial_mm, a.radial_mm, a.revs, a.damped};
    const std::vector<double> speeds = a.rpm.empty() ? std::vector<double>{cfg.cut.spindle_rpm} : a.rpm;
    // The job's speed range, as lobes checks it: a speed outside it is one the job does not describe.
    const config::Range job_speeds{
        "rpm", cfg.lobes.rpm_min, cfg.lobes.rpm_max, false, false, "the job's lobes.rpm_min .. lobes.rpm_max"};
    for (double rpm : a.rpm)
      if (auto p = config::range_problem("--rpm", rpm, job_speeds))
        throw config::ConfigError({config::Problem{cfg.source, {}, "--rpm", *p}});
    json out;
    if (!a.critical) {
      if (const auto failed = one_cut(a, cfg, structure, ov, speeds, out)) return *failed;
    } else {
      milling::CriticalStudy study{chosen, structure, ov, speeds, a.damped, a.radial_mm};
      out["critical"] = milling::critical_study(
          cfg, study, [](const std::string& line) { std::cerr << "[cut] " << line << '\n'; },
          [&](const milling::CutJob& job, double rpm, const milling::CriticalAtSpeed& c) {
            return a.hil_path.empty()
                       ? nlohmann::json()
                       : commission::hil_critical_json(a.hil_path, a.job_path, a.damped, job, rpm, c.depth_mm);
          });
    }
    out["config"] = cfg.source;
    out["structure"] = structure.name();
    if (!emit_json(a.json, out.dump(2), "cut")) return 1;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
    return 0;
  } catch (const config::ConfigError& e) {
    // Options and derived checks name themselves; problems in the job file come with file:line.
    for (const auto& p : e.problems())
      std::cerr << "robodamp cut: " << (p.mark.line > 0 ? p.to_string() : p.message) << '\n';
    return 2;
  }
}

}  // namespace

void register_cut(Registry& r) {
  auto a = std::make_shared<CutArgs>();
  CLI::App* sub = r.add("cut", "Time-domain cut with chatter detection; --critical: critical depth by simulation",
                        [a] { return run_cut(*a); });
  r.job(sub, a->job_path);
  sub->add_option("--structure", a->structure, "Which of the job's structures (default: its `structure`)");
  r.numbers(sub, "--pose", a->pose_deg, {"deg", -360.0, 360.0},
            "The robot's joint angles for the job's pose parts (config/robots/*.yaml)");
  r.numbers(sub, "--rpm", a->rpm, {"rpm", 0.0, 200000.0, true, false, "and within the job's lobes speed range"},
            "Spindle speed (several with --critical)");
  r.number(sub, "--axial-mm", a->axial_mm, {"mm", 0.0, 100.0, true, false}, "Axial depth (default: the job's)");
  r.number(sub, "--radial-mm", a->radial_mm, {"mm", 0.0, 1000.0, true, false, "and at most the tool's diameter"},
           "Radial depth (default: the job's)");
  r.whole_number(sub, "--revs", a->revs, {"(revolutions)", 2, 100000}, "Revolutions to simulate (default: the job's)");
  sub->add_flag("--critical", a->critical, "Critical depth at each --rpm by bisection on simulated cuts");
  sub->add_flag("--damped", a->damped,
                "With the damping controller running: the real Controller, the simulated plant with its actuator, "
                "limits and sensor, at the configuration's loop rate");
  sub->add_option("--controller", a->controller_path,
                  "Damping configuration to use instead of the job's (compare compensators)")
      ->check(CLI::ExistingFile);
  sub->add_option(
         "--hil", a->hil_path,
         "With --critical: also the critical depth through the HIL emulator, a cell configuration for the job's "
         "robot with can.interface unix:... (robodamp plant and the controller as two processes, lockstep)")
      ->check(CLI::ExistingFile);
  r.json(sub, a->json, "The result");
  r.plot_dir(sub, a->plot_dir, "displacement, force, spectrum and surface plots");
}

}  // namespace robodamp::apps
