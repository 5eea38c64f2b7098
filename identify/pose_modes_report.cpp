#include "identify/pose_modes_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

#include "analysis/pose_mode_check.hpp"
#include "analysis/pose_schedule.hpp"
#include "identify/pose_modes.hpp"
#include "plot/gnuplot.hpp"
#include "robot/modal_map.hpp"

namespace robodamp::identify {

namespace {

using nlohmann::json;

double error_pct(double value, double truth) { return 100.0 * (value / truth - 1.0); }

json row_json(const analysis::ModeCheckRow& r) {
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"pose", r.pose},
          {"joints_deg", r.joints_deg},
          {"role", r.held_out ? "held out" : "map"},
          {"measured_hz", r.measured_hz},
          {"measured_damping_ratio", r.measured_damping_ratio},
          {"measured_stiffness_n_per_m", r.measured_stiffness_n_per_m},
          {"model_hz", num(r.model_hz)},
          {"model_stiffness_n_per_m", num(r.model_stiffness_n_per_m)},
          {"mapped_hz", num(r.mapped_hz)},
          {"mapped_damping_ratio", num(r.mapped_damping_ratio)},
          {"mapped_stiffness_n_per_m", num(r.mapped_stiffness_n_per_m)},
          {"freq_sigma_pct", num(r.freq_sigma_pct)},
          {"damping_sigma_pct", num(r.damping_sigma_pct)},
          {"stiffness_sigma_pct", num(r.stiffness_sigma_pct)},
          {"nearest_measured_deg", r.nearest_measured_deg}};
}

// A number in a column, "-" where there is none (no model mode within 25 %).
std::string cell(double v, const char* format, int width) {
  char b[32];
  if (std::isfinite(v))
    std::snprintf(b, sizeof b, format, v);
  else
    std::snprintf(b, sizeof b, "%*s", width, "-");
  return b;
}

void row_text(const analysis::ModeCheckRow& r, std::ostringstream& t) {
  char b[320];
  std::snprintf(b, sizeof b, "  %-10s %-9s %8.2f %s %s %s %s %s   %s %s %s %7.1f\n", r.pose.c_str(),
                r.held_out ? "held out" : "map", r.measured_hz, cell(r.model_hz, "%8.2f", 8).c_str(),
                cell(error_pct(r.model_hz, r.measured_hz), "%+7.2f", 7).c_str(), cell(r.mapped_hz, "%8.2f", 8).c_str(),
                cell(error_pct(r.mapped_hz, r.measured_hz), "%+7.2f", 7).c_str(),
                cell(r.freq_sigma_pct, "%6.2f", 6).c_str(),
                cell(error_pct(r.model_stiffness_n_per_m, r.measured_stiffness_n_per_m), "%+7.1f", 7).c_str(),
                cell(error_pct(r.mapped_stiffness_n_per_m, r.measured_stiffness_n_per_m), "%+7.1f", 7).c_str(),
                cell(r.stiffness_sigma_pct, "%6.1f", 6).c_str(), r.nearest_measured_deg);
  t << b;
}

// How each measured mode is interpolated between the poses (robot::TrackForm): each quantity against the
// model's mode or as the measured values, the form that predicted the measured poses better when each was
// left out in turn, with both forms' errors.
json print_forms(const std::vector<robot::TrackForm>& forms, std::ostringstream& t) {
  json out = json::array();
  t << "  interpolated between the poses (each quantity in the form that predicts each measured pose better from the\n"
       "  others: against the model's mode, or the measured values on their own; leave-one-out RMS in brackets):\n";
  for (const robot::TrackForm& f : forms) {
    const double lo = f.min_hz, hi = f.max_hz;
    const auto form = [&](const char* what, const robot::QuantityForm& q, double scale, const char* unit) {
      char b[200];
      std::snprintf(b, sizeof b, "%s %s (own %.3g, against the model %.3g%s)", what,
                    q.own ? "own" : "against the model", scale * q.own_rms, scale * q.model_rms, unit);
      return std::string(b);
    };
    char head[160];
    std::snprintf(head, sizeof head, "    %.2f-%.2f Hz (%d poses", lo, hi, f.measured_poses);
    if (f.model_index < 0)
      t << head << ", no model mode follows it): every quantity the measured values on their own\n";
    else
      t << head << ", the model's mode " << f.model_index + 1 << "): " << form("frequency", f.freq, 100.0, " %") << "; "
        << form("damping", f.damping, 100.0, " %") << ";\n      " << form("participation", f.stiffness, 1.0, " 1/kg")
        << '\n';
    const auto qj = [](const robot::QuantityForm& q) {
      return json{
          {"form", q.own ? "own" : "against the model"}, {"own_loo_rms", q.own_rms}, {"model_loo_rms", q.model_rms}};
    };
    out.push_back({{"freq_hz", {lo, hi}},
                   {"measured_poses", f.measured_poses},
                   {"model_mode", f.model_index < 0 ? json(nullptr) : json(f.model_index + 1)},
                   {"frequency", qj(f.freq)},
                   {"damping", qj(f.damping)},
                   {"participation", qj(f.stiffness)}});
  }
  return out;
}

}  // namespace

PoseModesReport pose_modes_map_report(const config::RobotModelConfig& model,
                                      const std::vector<std::string>& measurements,
                                      const std::vector<std::string>& hold_out, int modes) {
  PoseMeasurements pm = read_pose_measurements(measurements);
  check_against_model(pm, model);
  const PoseModesIdentified id = identify_pose_modes(pm, hold_out);
  const int count = pm.modes > 0 ? pm.modes : modes;
  config::RobotModelConfig prior = model, mapped = model;
  prior.measured_modes.reset();
  mapped.measured_modes = id.measured;
  const int axis = id.measured.axis;
  std::vector<analysis::ModeCheckRow> rows =
      analysis::check_pose_modes(prior, mapped, id.measured.poses, false, axis, count);
  for (auto& r : analysis::check_pose_modes(prior, mapped, id.held_out, true, axis, count))
    rows.push_back(std::move(r));
  std::ostringstream t;
  t << "robot " << model.name << ": modes identified at " << id.measured.poses.size() << " measured pose(s) along "
    << (axis == 0 ? "x" : "y") << " (" << pm.band_min_hz << "-" << pm.band_max_hz << " Hz), the model's " << count
    << " lowest corrected towards them; " << id.held_out.size() << " held out\n"
    << "  frequency: measured, the model's and the map's (error %, one sigma %); modal stiffness: the model's and the\n"
    << "  map's error %, the map's sigma %; the distance to the nearest pose in the map (deg)\n"
    << "  pose       role      measured    model   err %   mapped   err %  sigma   k model k mapped sigma nearest\n";
  json out_rows = json::array();
  double worst_model = 0.0, worst_mapped = 0.0;
  int model_missed = 0, map_missed = 0;  // held-out modes with no mode within 25 %
  for (const auto& r : rows) {
    row_text(r, t);
    out_rows.push_back(row_json(r));
    if (!r.held_out) continue;
    if (std::isfinite(r.model_hz))
      worst_model = std::max(worst_model, std::abs(error_pct(r.model_hz, r.measured_hz)));
    else
      ++model_missed;
    if (std::isfinite(r.mapped_hz))
      worst_mapped = std::max(worst_mapped, std::abs(error_pct(r.mapped_hz, r.measured_hz)));
    else
      ++map_missed;
  }
  if (!id.held_out.empty()) {
    char b[300];
    std::snprintf(
        b, sizeof b,
        "  at the held-out poses the largest frequency error: the model %.2f %% (%d mode(s) it has not within 25 %%), "
        "the map %.2f %% (%d)\n",
        worst_model, model_missed, worst_mapped, map_missed);
    t << b;
  }
  const json forms = print_forms(robot::ModalMap(mapped, axis, count).forms(), t);
  PoseModesReport out;
  out.json = {{"model", model.source}, {"axis", axis == 0 ? "x" : "y"},
              {"modes", count},        {"band_hz", {pm.band_min_hz, pm.band_max_hz}},
              {"rows", out_rows},      {"modal_fit_error_pct", id.fit_error_pct},
              {"interpolated", forms}};
  if (!id.held_out.empty()) {
    out.json["held_out_worst_freq_error_pct"] = {{"model", worst_model}, {"mapped", worst_mapped}};
    out.json["held_out_modes_missed"] = {{"model", model_missed}, {"mapped", map_missed}};
  }
  out.text = t.str();
  out.mapped = std::move(mapped);
  return out;
}

void require_measured_modes(const config::RobotModelConfig& model) {
  if (!model.measured_modes)
    throw config::ConfigError({config::Problem{
        model.source,
        {},
        "measured_modes",
        "the model has no measured modes: give --measurements (robodamp measure --poses) to add them"}});
}

PoseModesReport pose_modes_at_report(const config::RobotModelConfig& model, const std::vector<double>& q, int modes) {
  require_measured_modes(model);
  const int axis = model.measured_modes->axis;
  config::RobotModelConfig prior = model;
  prior.measured_modes.reset();
  const analysis::PoseModes before = analysis::pose_modes(prior, q, axis, modes),
                            after = analysis::pose_modes(model, q, axis, modes);
  std::ostringstream t;
  char b[320];
  std::snprintf(b, sizeof b,
                "robot %s at %s: its %zu lowest modes along %s, corrected by the modes measured at %zu pose(s); the\n"
                "  nearest %.1f deg away in joint space. Mapped value (one sigma %%)\n",
                model.name.c_str(), config::describe_pose(q).c_str(), after.modes.size(), axis == 0 ? "x" : "y",
                model.measured_modes->poses.size(), after.nearest_measured_deg);
  t << b << "  mode   model Hz   mapped Hz  sigma %   damping ratio  sigma %   stiffness N/m  sigma %   measured at\n";
  json rows = json::array();
  for (std::size_t i = 0; i < after.modes.size(); ++i) {
    const auto& m = after.modes[i];
    const robot::ModeCorrection c = i < after.corrections.size() ? after.corrections[i] : robot::ModeCorrection{};
    const double model_hz = c.measured_only() || static_cast<std::size_t>(c.model_index) >= before.modes.size()
                                ? NAN
                                : before.modes[static_cast<std::size_t>(c.model_index)].natural_freq_hz;
    char model_col[16] = "       -";
    if (std::isfinite(model_hz)) std::snprintf(model_col, sizeof model_col, "%8.2f", model_hz);
    std::snprintf(b, sizeof b, "  %4zu   %s    %8.2f  %7.2f   %13.4f  %7.1f   %13.4g  %7.1f   %d pose(s)%s\n", i + 1,
                  model_col, m.natural_freq_hz, 100.0 * c.freq_sigma, m.damping_ratio, 100.0 * c.damping_sigma,
                  m.stiffness_n_per_m, 100.0 * c.stiffness_sigma, c.measured_poses,
                  c.measured_only() ? ", from the measurements alone" : "");
    t << b;
    rows.push_back({{"model_hz", std::isfinite(model_hz) ? json(model_hz) : json(nullptr)},
                    {"measured_only", c.measured_only()},
                    {"freq_hz", m.natural_freq_hz},
                    {"freq_sigma_pct", 100.0 * c.freq_sigma},
                    {"damping_ratio", m.damping_ratio},
                    {"damping_sigma_pct", 100.0 * c.damping_sigma},
                    {"stiffness_n_per_m", m.stiffness_n_per_m},
                    {"stiffness_sigma_pct", 100.0 * c.stiffness_sigma},
                    {"measured_poses", c.measured_poses}});
  }
  PoseModesReport out;
  out.json = {{"model", model.source},
              {"joints_deg", q},
              {"axis", axis == 0 ? "x" : "y"},
              {"nearest_measured_deg", after.nearest_measured_deg},
              {"modes", rows}};
  out.text = t.str();
  return out;
}

void add_pose_modes_sweep(PoseModesReport& r, const config::RobotModelConfig& model, const std::vector<double>& q,
                          int vary_joint, int modes) {
  if (vary_joint < 1 || static_cast<std::size_t>(vary_joint) > q.size())
    throw std::invalid_argument("--vary " + std::to_string(vary_joint) + ": the plot's joint is one of 1.." +
                                std::to_string(q.size()));
  config::RobotModelConfig prior = model;
  prior.measured_modes.reset();
  const int axis = model.measured_modes->axis;
  const std::size_t joint = static_cast<std::size_t>(vary_joint - 1);
  const auto sweep = analysis::sweep_pose_modes(prior, model, q, joint, 121, axis, modes);
  std::ostringstream data;
  json points = json::array();
  std::size_t curves = 0;
  for (const auto& p : sweep) curves = std::max(curves, p.mapped_hz.size());
  for (const auto& p : sweep) {
    data << p.joint_deg;
    for (std::size_t k = 0; k < curves; ++k) {
      const double f = k < p.mapped_hz.size() ? p.mapped_hz[k] : NAN,
                   s = k < p.mapped_hz.size() ? p.freq_sigma_pct[k] / 100.0 : 0.0;
      data << ' ' << plot::num(k < p.model_hz.size() ? p.model_hz[k] : NAN) << ' ' << plot::num(f) << ' '
           << plot::num(f * std::exp(-2.0 * s)) << ' ' << plot::num(f * std::exp(2.0 * s));
    }
    data << '\n';
    points.push_back({{"joint_deg", p.joint_deg},
                      {"model_hz", p.model_hz},
                      {"mapped_hz", p.mapped_hz},
                      {"freq_sigma_pct", p.freq_sigma_pct}});
  }
  data << "\n\n";
  for (const auto& p : model.measured_modes->poses)
    for (const auto& m : p.modes) data << p.joints_deg[joint] << ' ' << m.natural_freq_hz << '\n';
  r.json["sweep"] = {{"joint", vary_joint}, {"points", points}};
  r.plot_data = data.str();
  r.curves = curves;
  r.model_curve.assign(curves, false);
  for (const auto& p : sweep)
    for (std::size_t k = 0; k < curves && k < p.model_hz.size(); ++k)
      if (std::isfinite(p.model_hz[k])) r.model_curve[k] = true;
}

std::string plot_pose_modes_sweep(const PoseModesReport& r, int vary_joint, const std::string& path) {
  std::ostringstream gp;
  gp << "set grid; set key outside right; set xlabel 'joint " << vary_joint << " (deg), the others at the pose shown'; "
     << "set ylabel 'frequency (Hz)'; set title 'modes along joint " << vary_joint
     << ": the map (line, band 2 sigma), the model alone (dashed), measured (points)'; plot ";
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"};
  for (int k = 0; k < static_cast<int>(r.curves); ++k) {
    const int c = 2 + 4 * k;
    const std::string colour = colours[k % 6];
    gp << (k ? ", " : "") << "DATA index 0 u 1:" << c + 2 << ":" << c + 3
       << " w filledcurves fs transparent solid 0.2 lc rgb '" << colour << "' notitle, '' index 0 u 1:" << c + 1
       << " w l lw 2 lc rgb '" << colour << "' t 'mode " << k + 1 << " mapped";
    if (r.model_curve[static_cast<std::size_t>(k)])  // a mode the measurements alone give has no model line
      gp << "', '' index 0 u 1:" << c << " w l dt 2 lc rgb '" << colour << "' t 'mode " << k + 1 << " model'";
    else
      gp << " (measured only)'";
  }
  gp << ", DATA index 1 u 1:2 w p pt 7 ps 1.5 lc rgb 'black' t 'measured'";
  return plot::run_gnuplot(gp.str(), r.plot_data, path);
}

}  // namespace robodamp::identify
