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

json candidate_json(const tune::Candidate& c) {
  return {{"gain_ns_per_m", c.gain_ns_per_m},
          {"polarity", c.polarity},
          {"fz_hz", c.fz_hz},
          {"zeta_z", c.zeta_z},
          {"fp_hz", c.fp_hz},
          {"zeta_p", c.zeta_p},
          {"fa_hz", c.fa_hz},
          {"fb_hz", c.fb_hz}};
}

json evaluation_json(const tune::Evaluation& e) {
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j = {{"candidate", candidate_json(e.candidate)},
            {"stable", e.stable},
            {"gain_margin_db", finite(e.gain_margin_db)},
            {"phase_margin_deg", finite(e.phase_margin_deg)},
            {"delay_margin_ms", finite(e.delay_margin_ms)},
            {"k_max_ns_per_m", finite(e.k_max_ns_per_m)},
            {"worst_mode_phase_deg", e.worst_mode_phase_deg},
            {"min_depth_mm", e.min_depth_mm},
            {"floor_ratio", finite(e.floor_ratio)},
            {"accurate_min_mm", finite(e.accurate_min_mm)},
            {"accurate_min_rpm", e.accurate_min_rpm},
            {"open_minima_ratio", finite(e.open_minima_ratio)},
            {"depth_at_speed_mm", e.depth_at_speed_mm},
            {"floors_mm", e.floors_mm},
            {"at_open_minima_mm", e.at_open_minima_mm},
            {"peak_m_per_n", e.peak_m_per_n},
            {"objective", finite(e.objective)},
            {"peak_coil_force_n", e.peak_coil_force_n},
            {"peak_command_v", e.peak_command_v},
            {"peak_slew_v_per_s", e.peak_slew_v_per_s},
            {"actuator_use", e.actuator_use},
            {"quiet_command_rms_v", e.quiet_command_rms_v},
            {"feasible", e.feasible()},
            {"binding", e.binding},
            {"plant", e.plant}};
  if (!std::isnan(e.worst_mode_improvement_pct))  // --no-worse-mode only
    j["worst_mode_improvement_pct"] = finite(e.worst_mode_improvement_pct);
  return j;
}

json evaluation_json_with_plants(const tune::Evaluation& e) {
  json j = evaluation_json(e);
  if (!e.per_plant.empty()) {
    j["per_plant"] = json::array();
    for (const auto& p : e.per_plant) j["per_plant"].push_back(evaluation_json(p));
  }
  return j;
}

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

// The configuration's text with the compensator block, the gain and the polarity of the tuned candidate.
void print_row(const char* name, const tune::Evaluation& e) {
  std::printf(
      "  %-6s K %8.0f N s/m pol %+d | K_max %8.0f  GM %6.1f dB  PM %6.1f deg  DM %6.2f ms  modes within %.0f deg | ",
      name, e.candidate.gain_ns_per_m, e.candidate.polarity, e.k_max_ns_per_m, e.gain_margin_db, e.phase_margin_deg,
      e.delay_margin_ms, e.worst_mode_phase_deg);
  if (e.quiet_command_rms_v > 0.0) std::printf("quiet command %.4f V RMS | ", e.quiet_command_rms_v);
  if (e.actuator_use > 0.0)
    std::printf("impact: %.1f N coil, %.2f V, %.0f V/s (%.0f %% of a limit) | ", e.peak_coil_force_n, e.peak_command_v,
                e.peak_slew_v_per_s, 100.0 * e.actuator_use);
  if (e.peak_m_per_n > 0.0)
    std::printf("closed-loop peak %.4g m/N", e.peak_m_per_n);
  else
    std::printf(
        "min depth %.3f mm at %.0f rpm and %.3f mm at the job's speed (sampled-loop SDM), open minima x%.2f; "
        "zero-order preview: min %.3f mm, floors x%.2f",
        e.accurate_min_mm, e.accurate_min_rpm, e.depth_at_speed_mm, e.open_minima_ratio, e.min_depth_mm, e.floor_ratio);
  std::printf("%s\n", e.feasible() ? "" : (" (violates " + e.binding + ")").c_str());
}

// The plants the candidate is tuned for: --config, each --also, and with --shift-pct each of them with its
// modes shifted down and up.
std::vector<tune::Evaluator> make_plants(const TuneArgs& a, const std::optional<config::MillingConfig>& job) {
  std::vector<std::string> paths{a.config_path};
  paths.insert(paths.end(), a.also_paths.begin(), a.also_paths.end());
  std::vector<tune::Evaluator> plants;
  for (const auto& path : paths) {
    const config::Config cfg = config::load_config_file(path);
    plants.emplace_back(cfg, job, a.settings, path);
    if (!a.shift_pct) continue;
    for (const double sign : {-1.0, 1.0}) {
      char name[64];
      std::snprintf(name, sizeof name, " (modes %+.3g %%)", sign * *a.shift_pct);
      plants.emplace_back(tune::with_shifted_modes(cfg, 1.0 + sign * *a.shift_pct / 100.0), job, a.settings,
                          path + name);
    }
  }
  return plants;
}

struct Compared {
  std::string name;
  config::Config cfg;
  tune::Evaluation e;
};

// The plant's hand designs (C1, C2, C3 at the configured gain and the recommended polarity), and the tuned one.
std::vector<Compared> compare(const tune::Evaluator& p, const tune::Evaluation& tuned, bool hand_designs) {
  std::vector<Compared> out;
  if (hand_designs)
    for (const auto model :
         {config::CompensatorModel::kC1, config::CompensatorModel::kC2, config::CompensatorModel::kC3}) {
      config::Config c = p.base();
      for (auto& b : c.controller.chain)
        if (b.kind == config::BlockKind::kCompensator) b.model = model;
      c.controller.polarity = analysis::analyse(analysis::LoopModel(c)).recommended_polarity;
      out.push_back({config::to_string(model), c, p.assess(c)});
    }
  out.push_back({"tuned", tune::with_candidate(p.base(), tuned.candidate), tuned});
  return out;
}

// One plant: the rows, the damped floor in each interval between the open loop's lobe peaks, the
// improvement at each mode.
void report_plant(const tune::Evaluator& p, const std::vector<Compared>& rows, json& out) {
  std::printf("plant %s\n", p.name().c_str());
  json j;
  for (const auto& r : rows) {
    print_row(r.name.c_str(), r.e);
    j[r.name] = evaluation_json(r.e);
  }
  if (!p.open_floors_mm().empty()) {
    std::printf(
        "  lobe floor between the open loop's peaks, and the limit at the open loop's floor speed, mm (zero-order "
        "preview: it steers the search):\n"
        "    %-15s %8s",
        "rpm", "open");
    for (const auto& r : rows) std::printf(" %8s %8s", r.name.c_str(), "at min");
    for (std::size_t i = 0; i < p.open_floors_mm().size(); ++i) {
      const auto& iv = p.open_intervals_rpm()[i];
      std::printf("\n    %6.0f - %6.0f %8.3f", iv.first, iv.second, p.open_floors_mm()[i]);
      for (const auto& r : rows)
        std::printf(" %8.3f %8.3f", i < r.e.floors_mm.size() ? r.e.floors_mm[i] : 0.0,
                    i < r.e.at_open_minima_mm.size() ? r.e.at_open_minima_mm[i] : 0.0);
      std::printf("   (open floor at %.0f rpm)", p.open_floor_rpm()[i]);
    }
    std::printf("\n");
  }
  std::printf("  improvement at each mode (%s peak within +-10 %%):", p.base().robot.frfs.front().name.c_str());
  std::vector<std::vector<tune::ModeImprovement>> mi;
  for (const auto& r : rows) mi.push_back(p.mode_improvements(r.cfg));
  for (std::size_t k = 0; k < p.base().robot.frfs.front().modes.size(); ++k) {
    std::printf("\n    %6.2f Hz", p.base().robot.frfs.front().modes[k].natural_freq_hz);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (k < mi[i].size()) std::printf("  %s %+7.1f %%", rows[i].name.c_str(), mi[i][k].improvement_pct);
      if (k < mi[i].size()) j[rows[i].name]["mode_improvement_pct"].push_back(mi[i][k].improvement_pct);
    }
  }
  std::printf("\n");
  out[p.name()] = j;
}

// The open loop's lobes with each compared controller's, on the first plant.
std::string plot_lobes(const tune::Evaluator& p, const std::vector<Compared>& rows, const std::string& path) {
  // One data block per curve: the damped speeds are stepped to the loop rate, each its own.
  std::vector<std::vector<std::pair<double, double>>> curves{p.open_curve_mm()};
  for (const auto& r : rows) curves.push_back(p.damped_curve_mm(r.cfg));
  std::ostringstream data;
  for (const auto& c : curves) {
    for (const auto& [rpm, mm] : c) {
      char line[96];
      std::snprintf(line, sizeof line, "%.10g %.10g\n", rpm, std::isfinite(mm) ? mm : NAN);
      data << line;
    }
    data << "\n\n";
  }
  double y_max = 3.0 * p.open_min_depth_mm();
  for (const auto& r : rows)
    if (r.e.accurate_min_mm > 0.0 && std::isfinite(r.e.accurate_min_mm))
      y_max = std::max(y_max, 4.0 * r.e.accurate_min_mm);
  std::ostringstream s;
  s << "set title 'Stability lobes by semi-discretization (open loop: SDM; damped: sampled-loop SDM), "
    << "hand designs and robodamp tune (" << p.name() << ")' noenhanced\n"
    << "set grid\nset xlabel 'spindle speed (rpm)'\nset ylabel 'limiting axial depth b_lim (mm)'\n"
    << "set key bottom right opaque box\nset yrange [0:" << y_max << "]\n";
  const char* colours[] = {"#7f8c8d", "#27ae60", "#e67e22", "#8e44ad", "#2471a3"};
  s << "plot DATA index 0 u 1:2 w l lw 2 lc rgb '" << colours[0] << "' t 'open loop'";
  for (std::size_t i = 0; i < rows.size(); ++i)
    s << ", DATA index " << i + 1 << " u 1:2 w l lw 2 lc rgb '" << colours[(i + 1) % 5] << "' t '" << rows[i].name
      << "'";
  s << '\n';
  return run_gnuplot(s.str(), data.str(), path);
}

// How far the tuned loop holds as the modes move (a weak point is a warning, as in commission and analyze).
void report_robustness(const config::Config& tuned, json& report) {
  const tune::Robustness rb = tune::robustness(tuned);
  std::printf("the tuned loop stays stable and damps its modes from -%.1f %% to +%.1f %% of mode shift%s%s%s\n",
              rb.down.pct, rb.up.pct, rb.down.reason.empty() ? "" : ("; " + rb.down.reason).c_str(),
              rb.up.reason.empty() ? "" : ("; " + rb.up.reason).c_str(),
              rb.pct() < tune::kRobustShiftWarnPct
                  ? " (WARNING: under +-5 %: a pose or tool change may move the modes further)"
                  : "");
  report["robustness"] = {
      {"down_pct", rb.down.pct}, {"up_pct", rb.up.pct}, {"down_reason", rb.down.reason}, {"up_reason", rb.up.reason}};
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
  std::printf(
      "verified (%s, %zu speeds): damped minimum %.3f mm at %.1f rpm (open loop %.3f mm, SDM), at the job's "
      "%.1f rpm %.3f mm\n  the time-domain cut with the real Controller: %.3f mm at the job's speed (%+.1f %%), "
      "%.3f mm at the minimum's speed (%+.1f %%)\n",
      v.method.c_str(), v.damped_curve_mm.size(), v.min_depth_mm, v.min_rpm, v.open_min_depth_mm, v.speed_rpm,
      v.depth_at_speed_mm, v.time_domain_at_speed_mm, (v.time_domain_at_speed_mm / v.depth_at_speed_mm - 1.0) * 100.0,
      v.time_domain_at_min_mm, (v.time_domain_at_min_mm / v.min_depth_mm - 1.0) * 100.0);
  report["verified"] = {{"method", v.method},
                        {"min_depth_mm", v.min_depth_mm},
                        {"min_rpm", v.min_rpm},
                        {"open_min_depth_mm", v.open_min_depth_mm},
                        {"speed_rpm", v.speed_rpm},
                        {"depth_at_speed_mm", v.depth_at_speed_mm},
                        {"time_domain_at_speed_mm", v.time_domain_at_speed_mm},
                        {"time_domain_at_min_mm", v.time_domain_at_min_mm},
                        {"time_domain_agrees", v.time_domain_agrees()}};
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
  const std::vector<tune::Evaluator> plants = make_plants(a, job);
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
              {"best", evaluation_json_with_plants(r.best)}};
  json per_plant;
  for (std::size_t i = 0; i < plants.size(); ++i) {
    const bool nominal = !a.shift_pct || i % 3 == 0;
    const auto rows = compare(plants[i], plants.size() == 1 ? r.best : r.best.per_plant[i], nominal);
    report_plant(plants[i], rows, per_plant);
    if (const std::string plot = plot_file(a.plot_dir, a.plot_path, "tune_lobes.png"); i == 0 && !plot.empty() && job) {
      const std::string failed = plot_lobes(plants[i], rows, plot);
      if (!failed.empty()) throw std::runtime_error("the lobes plot: " + failed);
      std::printf("wrote %s\n", plot.c_str());
    }
  }
  report["plants"] = per_plant;
  if (plants.size() > 1) print_row("worst", r.best);
  json history = json::array();
  for (const auto& e : r.history) history.push_back(evaluation_json(e));
  report["history"] = history;
  if (!r.best.feasible()) {
    std::cerr << "robodamp tune: no candidate met every constraint; the closest violates " << r.best.binding
              << ": nothing written\n";
    if (!emit_json(a.json, report.dump(2), "tune")) return 1;
    return 3;
  }
  report_robustness(tune::with_candidate(plants.front().base(), r.best.candidate), report);
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
