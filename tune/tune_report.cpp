#include "tune/tune_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "fields/json.hpp"
#include "plot/gnuplot.hpp"
#include "tune/robustness.hpp"

namespace robodamp::tune {

using nlohmann::json;

namespace {

// printf into a string.
__attribute__((format(printf, 1, 2))) std::string format(const char* f, ...) {
  va_list args, again;
  va_start(args, f);
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, f, args);
  va_end(args);
  std::string out(static_cast<std::size_t>(std::max(n, 0)), '\0');
  std::vsnprintf(out.data(), out.size() + 1, f, again);
  va_end(again);
  return out;
}

}  // namespace

json candidate_json(const Candidate& c) {
  return {{"gain_ns_per_m", c.gain_ns_per_m},
          {"polarity", c.polarity},
          {"fz_hz", c.fz_hz},
          {"zeta_z", c.zeta_z},
          {"fp_hz", c.fp_hz},
          {"zeta_p", c.zeta_p},
          {"fa_hz", c.fa_hz},
          {"fb_hz", c.fb_hz}};
}

json evaluation_json(const Evaluation& e) {
  const auto finite = fields::finite_or_null;
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

json evaluation_json_with_plants(const Evaluation& e) {
  json j = evaluation_json(e);
  if (!e.per_plant.empty()) {
    j["per_plant"] = json::array();
    for (const auto& p : e.per_plant) j["per_plant"].push_back(evaluation_json(p));
  }
  return j;
}

std::string evaluation_row(const std::string& name, const Evaluation& e) {
  std::string s = format(
      "  %-6s K %8.0f N s/m pol %+d | K_max %8.0f  GM %6.1f dB  PM %6.1f deg  DM %6.2f ms  modes within %.0f deg | ",
      name.c_str(), e.candidate.gain_ns_per_m, e.candidate.polarity, e.k_max_ns_per_m, e.gain_margin_db,
      e.phase_margin_deg, e.delay_margin_ms, e.worst_mode_phase_deg);
  if (e.quiet_command_rms_v > 0.0) s += format("quiet command %.4f V RMS | ", e.quiet_command_rms_v);
  if (e.actuator_use > 0.0)
    s += format("impact: %.1f N coil, %.2f V, %.0f V/s (%.0f %% of a limit) | ", e.peak_coil_force_n, e.peak_command_v,
                e.peak_slew_v_per_s, 100.0 * e.actuator_use);
  if (e.peak_m_per_n > 0.0)
    s += format("closed-loop peak %.4g m/N", e.peak_m_per_n);
  else
    s += format(
        "min depth %.3f mm at %.0f rpm and %.3f mm at the job's speed (sampled-loop SDM), open minima x%.2f; "
        "zero-order preview: min %.3f mm, floors x%.2f",
        e.accurate_min_mm, e.accurate_min_rpm, e.depth_at_speed_mm, e.open_minima_ratio, e.min_depth_mm, e.floor_ratio);
  return s + (e.feasible() ? "" : " (violates " + e.binding + ")") + "\n";
}

std::vector<Evaluator> tuning_plants(const std::vector<std::string>& config_paths, std::optional<double> shift_pct,
                                     const std::optional<config::MillingConfig>& job, const TuneSettings& settings) {
  std::vector<Evaluator> plants;
  for (const auto& path : config_paths) {
    const config::Config cfg = config::load_config_file(path);
    plants.emplace_back(cfg, job, settings, path);
    if (!shift_pct) continue;
    for (const double sign : {-1.0, 1.0})
      plants.emplace_back(with_shifted_modes(cfg, 1.0 + sign * *shift_pct / 100.0), job, settings,
                          path + format(" (modes %+.3g %%)", sign * *shift_pct));
  }
  return plants;
}

std::vector<ComparedDesign> compare_designs(const Evaluator& p, const Evaluation& tuned, bool hand_designs) {
  std::vector<ComparedDesign> out;
  if (hand_designs)
    for (const auto model :
         {config::CompensatorModel::kC1, config::CompensatorModel::kC2, config::CompensatorModel::kC3}) {
      config::Config c = p.base();
      for (auto& b : c.controller.chain)
        if (b.kind == config::BlockKind::kCompensator) b.model = model;
      c.controller.polarity = analysis::analyse(analysis::LoopModel(c)).recommended_polarity;
      out.push_back({config::to_string(model), c, p.assess(c)});
    }
  out.push_back({"tuned", with_candidate(p.base(), tuned.candidate), tuned});
  return out;
}

std::string plant_report(const Evaluator& p, const std::vector<ComparedDesign>& rows, json& out) {
  std::string s = "plant " + p.name() + "\n";
  json j;
  for (const auto& r : rows) {
    s += evaluation_row(r.name, r.e);
    j[r.name] = evaluation_json(r.e);
  }
  if (!p.open_floors_mm().empty()) {
    s += format(
        "  lobe floor between the open loop's peaks, and the limit at the open loop's floor speed, mm (zero-order "
        "preview: it steers the search):\n"
        "    %-15s %8s",
        "rpm", "open");
    for (const auto& r : rows) s += format(" %8s %8s", r.name.c_str(), "at min");
    for (std::size_t i = 0; i < p.open_floors_mm().size(); ++i) {
      const auto& iv = p.open_intervals_rpm()[i];
      s += format("\n    %6.0f - %6.0f %8.3f", iv.first, iv.second, p.open_floors_mm()[i]);
      for (const auto& r : rows)
        s += format(" %8.3f %8.3f", i < r.e.floors_mm.size() ? r.e.floors_mm[i] : 0.0,
                    i < r.e.at_open_minima_mm.size() ? r.e.at_open_minima_mm[i] : 0.0);
      s += format("   (open floor at %.0f rpm)", p.open_floor_rpm()[i]);
    }
    s += "\n";
  }
  s += format("  improvement at each mode (%s peak within +-10 %%):", p.base().robot.frfs.front().name.c_str());
  std::vector<std::vector<ModeImprovement>> mi;
  for (const auto& r : rows) mi.push_back(p.mode_improvements(r.cfg));
  for (std::size_t k = 0; k < p.base().robot.frfs.front().modes.size(); ++k) {
    s += format("\n    %6.2f Hz", p.base().robot.frfs.front().modes[k].natural_freq_hz);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (k < mi[i].size()) s += format("  %s %+7.1f %%", rows[i].name.c_str(), mi[i][k].improvement_pct);
      if (k < mi[i].size()) j[rows[i].name]["mode_improvement_pct"].push_back(mi[i][k].improvement_pct);
    }
  }
  out[p.name()] = j;
  return s + "\n";
}

std::string plot_compared_lobes(const Evaluator& p, const std::vector<ComparedDesign>& rows,
                                const std::string& png_path) {
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
  return plot::run_gnuplot(s.str(), data.str(), png_path);
}

std::string robustness_report(const config::Config& tuned, json& report) {
  const Robustness rb = robustness(tuned);
  report["robustness"] = {
      {"down_pct", rb.down.pct}, {"up_pct", rb.up.pct}, {"down_reason", rb.down.reason}, {"up_reason", rb.up.reason}};
  return format("the tuned loop stays stable and damps its modes from -%.1f %% to +%.1f %% of mode shift%s%s%s\n",
                rb.down.pct, rb.up.pct, rb.down.reason.empty() ? "" : ("; " + rb.down.reason).c_str(),
                rb.up.reason.empty() ? "" : ("; " + rb.up.reason).c_str(),
                rb.pct() < kRobustShiftWarnPct
                    ? " (WARNING: under +-5 %: a pose or tool change may move the modes further)"
                    : "");
}

std::string verification_report(const Verification& v, json& report) {
  report["verified"] = {{"method", v.method},
                        {"min_depth_mm", v.min_depth_mm},
                        {"min_rpm", v.min_rpm},
                        {"open_min_depth_mm", v.open_min_depth_mm},
                        {"speed_rpm", v.speed_rpm},
                        {"depth_at_speed_mm", v.depth_at_speed_mm},
                        {"time_domain_at_speed_mm", v.time_domain_at_speed_mm},
                        {"time_domain_at_min_mm", v.time_domain_at_min_mm},
                        {"time_domain_agrees", v.time_domain_agrees()}};
  return format(
      "verified (%s, %zu speeds): damped minimum %.3f mm at %.1f rpm (open loop %.3f mm, SDM), at the job's "
      "%.1f rpm %.3f mm\n  the time-domain cut with the real Controller: %.3f mm at the job's speed (%+.1f %%), "
      "%.3f mm at the minimum's speed (%+.1f %%)\n",
      v.method.c_str(), v.damped_curve_mm.size(), v.min_depth_mm, v.min_rpm, v.open_min_depth_mm, v.speed_rpm,
      v.depth_at_speed_mm, v.time_domain_at_speed_mm, (v.time_domain_at_speed_mm / v.depth_at_speed_mm - 1.0) * 100.0,
      v.time_domain_at_min_mm, (v.time_domain_at_min_mm / v.min_depth_mm - 1.0) * 100.0);
}

// How far the loop holds as the modes move (tune/robustness.hpp), with a warning under +-5 %.
std::string robustness_section(const config::Config& cfg, nlohmann::json& report) {
  const Robustness rb = robustness(cfg);
  report["robustness"] = {{"down_pct", rb.down.pct},
                          {"up_pct", rb.up.pct},
                          {"down_reason", rb.down.reason},
                          {"up_reason", rb.up.reason},
                          {"warn_below_pct", kRobustShiftWarnPct}};
  char line[160];
  std::snprintf(line, sizeof line,
                "  modes shifted together: the loop stays stable and damps its modes from -%.1f %% to +%.1f %%",
                rb.down.pct, rb.up.pct);
  std::string out = line;
  for (const auto* s : {&rb.down, &rb.up})
    if (!s->reason.empty()) out += "; " + s->reason;
  if (rb.pct() < kRobustShiftWarnPct) {
    std::snprintf(line, sizeof line,
                  "\n  WARNING: robust to only +-%.1f %% of mode shift (under +-%.0f %%: a pose or tool change may "
                  "move the modes further)",
                  rb.pct(), kRobustShiftWarnPct);
    out += line;
  }
  return out + "\n";
}

nlohmann::json search_report(const TuneCommand& cmd, const std::vector<Evaluator>& plants, const TuneResult& r,
                             bool has_job, const std::string& plot_path, std::FILE* out) {
  nlohmann::json report{{"config", cmd.config_path},
                        {"also", cmd.also_paths},
                        {"job", cmd.job_path},
                        {"best", evaluation_json_with_plants(r.best)}};
  nlohmann::json per_plant;
  for (std::size_t i = 0; i < plants.size(); ++i) {
    const bool nominal = !cmd.shift_pct || i % 3 == 0;
    const auto rows = compare_designs(plants[i], plants.size() == 1 ? r.best : r.best.per_plant[i], nominal);
    std::fputs(plant_report(plants[i], rows, per_plant).c_str(), out);
    if (i == 0 && !plot_path.empty() && has_job) {
      const std::string failed = plot_compared_lobes(plants[i], rows, plot_path);
      if (!failed.empty()) throw std::runtime_error("the lobes plot: " + failed);
      std::fprintf(out, "wrote %s\n", plot_path.c_str());
    }
  }
  report["plants"] = per_plant;
  if (plants.size() > 1) std::fputs(evaluation_row("worst", r.best).c_str(), out);
  nlohmann::json history = nlohmann::json::array();
  for (const auto& e : r.history) history.push_back(evaluation_json(e));
  report["history"] = history;
  return report;
}

}  // namespace robodamp::tune
