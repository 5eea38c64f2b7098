// `robodamp analyze`: stability, margins, the gain limit, the polarity and the predicted improvement of
// the damping loop (analysis/loop_report.hpp), with the harmonic notches' speed map, the pose schedule, the
// speed schedule, robustness and the job's limits at a spindle speed, as a table, JSON and plots.
#include "analysis/loop_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "analysis/notch_speed_map.hpp"
#include "analysis/pose_schedule.hpp"
#include "analysis/speed_schedule_check.hpp"
#include "fields/json.hpp"
#include "milling/study_report.hpp"
#include "apps/cli.hpp"
#include "config/milling_config.hpp"
#include "milling/live_stability.hpp"
#include "tune/robustness.hpp"
#include "apps/gnuplot.hpp"
#include <memory>

namespace robodamp::apps {

using nlohmann::json;

namespace {

using fields::number_or_null;

using fields::number_text;

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

// The speed map as JSON: every speed with the notches' phase at each mode, and the refused ranges.
json speed_map_json(const config::Config& cfg, const analysis::NotchSpeedMap& map) {
  json points = json::array();
  for (const auto& p : map.points)
    points.push_back({{"rpm", p.rpm},
                      {"stable", p.stable},
                      {"refused", p.refused},
                      {"reason", p.reason},
                      {"notch_phase_deg", p.notch_phase_deg}});
  json refused = json::array();
  for (const auto& [lo, hi] : map.refused_rpm) refused.push_back({{"from_rpm", lo}, {"to_rpm", hi}});
  return {{"config", cfg.source},
          {"teeth", cfg.spindle.teeth},
          {"mode_hz", map.points.empty() ? json::array() : json(map.points.front().mode_hz)},
          {"points", points},
          {"refused", refused}};
}

// The harmonic notches across spindle.rpm range: the refused speeds and the worst phase at each mode.
int print_speed_map(const config::Config& cfg, const JsonOut& out) {
  const analysis::NotchSpeedMap map = analysis::notch_speed_map(cfg);
  if (!emit_json(out, speed_map_json(cfg, map).dump(2), "analyze")) return 1;
  if (out.to_stdout()) return 0;
  if (map.points.empty()) {
    std::printf("no controller.harmonic_notch configured: nothing to sweep\n");
    return 0;
  }
  std::printf("harmonic notches across %.0f-%.0f rpm (%zu speeds, %d teeth):\n", map.points.front().rpm,
              map.points.back().rpm, map.points.size(), cfg.spindle.teeth);
  for (std::size_t k = 0; k < map.points.front().mode_hz.size(); ++k) {
    double worst = 0.0, at = 0.0;
    for (const auto& p : map.points)
      if (std::abs(p.notch_phase_deg[k]) > std::abs(worst)) worst = p.notch_phase_deg[k], at = p.rpm;
    std::printf("  %.2f Hz mode: the notches cost at most %+.1f deg (at %.0f rpm)\n", map.points.front().mode_hz[k],
                worst, at);
  }
  if (map.refused_rpm.empty()) std::printf("  no speed refused\n");
  for (const auto& [lo, hi] : map.refused_rpm) {
    std::string why;
    for (const auto& p : map.points)
      if (p.refused && p.rpm >= lo && p.rpm <= hi) {
        why = p.reason;
        break;
      }
    std::printf("  refused %.0f-%.0f rpm: %s; the notches park there\n", lo, hi, why.c_str());
  }
  return 0;
}

// pose_schedule: each region's set, analysed over its grid (analysis/pose_schedule.hpp); a region with no
// stable set throws ConfigError (exit 2).
int print_pose_schedule(const config::Config& cfg, const JsonOut& out) {
  const analysis::PoseScheduleAnalysis ps = analysis::analyse_pose_schedule(cfg);
  json regions = json::array();
  for (const auto& r : ps.regions) {
    const analysis::LoopModel centre(r.config);
    const analysis::AnalysisResult a = analysis::analyse(centre, r.gain_ns_per_m, r.polarity);
    regions.push_back({{"name", r.name},
                       {"centre_deg", r.centre_deg},
                       {"dominant_hz", r.dominant_hz},
                       {"dominant_min_hz", r.dominant_min_hz},
                       {"dominant_max_hz", r.dominant_max_hz},
                       {"grid_poses", r.grid_poses},
                       {"gain_ns_per_m", r.gain_ns_per_m},
                       {"polarity", r.polarity},
                       {"k_max_ns_per_m", r.k_max_ns_per_m},
                       {"k_max_pose_deg", r.k_max_pose_deg},
                       {"centre_gain_margin_db", number_or_null(a.margins.gain_margin_db)},
                       {"centre_phase_margin_deg", number_or_null(a.margins.phase_margin_deg)},
                       {"improvement_centre_pct", r.improvement_centre_pct},
                       {"worst_mode_improvement_pct", r.worst_mode_improvement_pct},
                       {"worst_mode_hz", r.worst_mode_hz},
                       {"worst_mode_pose_deg", r.worst_mode_pose_deg},
                       {"outside_band_pct", r.outside_band_pct ? json(*r.outside_band_pct) : json(nullptr)},
                       {"outside_band_hz", r.outside_band_hz ? json(*r.outside_band_hz) : json(nullptr)}});
  }
  const config::PoseScheduleConfig& sched = *cfg.pose_schedule;
  const json report = {{"config", cfg.source},
                       {"model", ps.model.source},
                       {"axis", sched.axis ? "y" : "x"},
                       {"damping_band_hz", {sched.damping_band_min_hz, sched.damping_band_max_hz}},
                       {"regions", regions}};
  if (!emit_json(out, report.dump(2), "analyze")) return 1;
  if (out.to_stdout()) return 0;
  std::printf("pose schedule of %s: robot model %s, actuator along %s\n", cfg.source.c_str(), ps.model.source.c_str(),
              cfg.pose_schedule->axis ? "y" : "x");
  std::printf("%-12s %-26s %-18s %9s %4s %9s %11s %9s %9s %8s\n", "region", "centre (deg)", "dominant (Hz)", "match Hz",
              "pol", "K N s/m", "K_max N s/m", "GM dB", "PM deg", "impr %");
  for (const auto& r : regions) {
    const std::string centre = config::describe_pose(r["centre_deg"].get<std::vector<double>>());
    char dom[40];
    std::snprintf(dom, sizeof dom, "%.2f-%.2f", r["dominant_min_hz"].get<double>(), r["dominant_max_hz"].get<double>());
    std::printf("%-12s %-26s %-18s %9.2f %+4d %9.0f %11.0f %9s %9s %8.1f\n", r["name"].get<std::string>().c_str(),
                centre.c_str(), dom, r["dominant_hz"].get<double>(), r["polarity"].get<int>(),
                r["gain_ns_per_m"].get<double>(), r["k_max_ns_per_m"].get<double>(),
                number_text(r["centre_gain_margin_db"], "%.1f").c_str(),
                number_text(r["centre_phase_margin_deg"], "%.1f").c_str(), r["improvement_centre_pct"].get<double>());
  }
  std::printf("K_max is the smallest over each region's %d^%zu grid; margins and improvement at its centre\n",
              cfg.pose_schedule->grid_points, cfg.pose_schedule->joints());
  std::printf(
      "the worst mode in the damping band %g-%g Hz over each region's grid (the smallest improvement of a robot mode's "
      "peak, %s within +-10 %%):\n",
      sched.damping_band_min_hz, sched.damping_band_max_hz,
      cfg.robot.frfs.empty() ? "-" : cfg.robot.frfs.front().name.c_str());
  for (const auto& r : regions) {
    const double w = r["worst_mode_improvement_pct"];
    std::printf("  %-12s %+7.1f %% at %.2f Hz at %s%s", r["name"].get<std::string>().c_str(), w,
                r["worst_mode_hz"].get<double>(),
                config::describe_pose(r["worst_mode_pose_deg"].get<std::vector<double>>()).c_str(),
                w < 0.0 ? ": worse than open loop there" : "");
    if (!r["outside_band_pct"].is_null())
      std::printf("; outside the band %+.1f %% at %.2f Hz", r["outside_band_pct"].get<double>(),
                  r["outside_band_hz"].get<double>());
    std::printf("\n");
  }
  return 0;
}

// With spindle.job and --spindle-rpm: the job's limits at that speed by the accurate method (the cell's live
// stability, milling/live_stability.hpp), each with its method.
void add_job_limits(const analysis::LoopModel& m, std::optional<double> rpm, json& report) {
  const config::Config& cfg = m.config();
  if (!rpm || cfg.spindle.job_resolved.empty()) return;
  milling::LiveStability live(config::load_milling_config(cfg.spindle.job_resolved), cfg.spindle.structure, {cfg});
  const milling::LiveLimits l = live.compute(*rpm, 0, cfg.controller.gain_ns_per_m);
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  report["job_limits"] = {{"rpm", *rpm},
                          {"depth_mm", live.depth_mm()},
                          {"open_mm", finite(l.open_mm)},
                          {"open_method", l.open_method},
                          {"damped_mm", finite(l.damped_mm)},
                          {"damped_method", l.method},
                          {"analysed_rpm", l.analysed_rpm},
                          {"damped_valid", l.damped_valid}};
}

// controller.speed_schedule: each controller and K its bands run, checked as a loop, with its weak points.
std::string speed_schedule_section(const config::Config& cfg, json& report) {
  if (!cfg.controller.speed_schedule) return {};
  std::ostringstream os;
  const auto loops = analysis::check_speed_schedule(cfg);
  os << "  speed schedule: " << cfg.controller.speed_schedule->bands.size()
     << " bands (robodamp schedule; K = 0 in a band "
     << "where the damper is worse than none); each controller and K they run, as a loop:\n";
  json j = json::array();
  for (const auto& l : loops) {
    char line[300];
    std::snprintf(
        line, sizeof line, "    controller %zu at K %6.0f N s/m (%zu band%s from %.0f rpm): %s, GM %s dB, %s\n",
        l.controller, l.gain_ns_per_m, l.bands, l.bands == 1 ? "" : "s", l.rpm_from, l.stable ? "stable" : "UNSTABLE",
        l.margins.gain_margin_db ? number_text(json(*l.margins.gain_margin_db), "%.1f").c_str() : "-",
        l.margins.phase_margin_deg ? ("PM " + number_text(json(*l.margins.phase_margin_deg), "%.1f") + " deg").c_str()
                                   : "no gain crossover");
    os << line;
    for (const auto& w : l.warnings) os << "      WARNING: " << w << "\n";
    for (const auto& n : l.notes) os << "      note: " << n << "\n";
    j.push_back({{"controller", l.controller},
                 {"gain_ns_per_m", l.gain_ns_per_m},
                 {"bands", l.bands},
                 {"stable", l.stable},
                 {"gain_margin_db", number_or_null(l.margins.gain_margin_db)},
                 {"phase_margin_deg", number_or_null(l.margins.phase_margin_deg)},
                 {"warnings", l.warnings},
                 {"notes", l.notes}});
  }
  report["speed_schedule"] = j;
  return os.str();
}

// How far the loop holds as the modes move (tune/robustness.hpp), with a warning under +-5 %.
std::string robustness_section(const config::Config& cfg, json& report) {
  const tune::Robustness rb = tune::robustness(cfg);
  report["robustness"] = {{"down_pct", rb.down.pct},
                          {"up_pct", rb.up.pct},
                          {"down_reason", rb.down.reason},
                          {"up_reason", rb.up.reason},
                          {"warn_below_pct", tune::kRobustShiftWarnPct}};
  char line[160];
  std::snprintf(line, sizeof line,
                "  modes shifted together: the loop stays stable and damps its modes from -%.1f %% to +%.1f %%",
                rb.down.pct, rb.up.pct);
  std::string out = line;
  for (const auto* s : {&rb.down, &rb.up})
    if (!s->reason.empty()) out += "; " + s->reason;
  if (rb.pct() < tune::kRobustShiftWarnPct) {
    std::snprintf(line, sizeof line,
                  "\n  WARNING: robust to only +-%.1f %% of mode shift (under +-%.0f %%: a pose or tool change may "
                  "move the modes further)",
                  rb.pct(), tune::kRobustShiftWarnPct);
    out += line;
  }
  return out + "\n";
}

// 0 stable, 3 unstable at the configured K, 1 plot failed.
int run_analyze(const AnalyzeArgs& a) {
  if (a.spindle_sweep) return print_speed_map(config::load_config_file(a.config_path), a.json);
  if (const config::Config cfg = config::load_config_file(a.config_path); cfg.pose_schedule && !a.base)
    return print_pose_schedule(cfg, a.json);
  const analysis::LoopModel model(config::load_config_file(a.config_path), a.spindle_rpm);
  const auto result = analysis::analyse(model);
  auto report = analysis::analysis_report(model, result);
  add_job_limits(model, a.spindle_rpm, report);
  std::string table = analysis::analysis_table(report) +
                      (result.stable ? robustness_section(model.config(), report) : std::string()) +
                      speed_schedule_section(model.config(), report);
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
