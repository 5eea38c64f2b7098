// `robodamp pose fit`: the robot model's joints fitted to measured TCP receptances (robot/pose_fit.hpp), the
// error before and after at each pose, the held-out poses apart.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/gnuplot.hpp"
#include "apps/pose_command.hpp"
#include "identify/modal_fit.hpp"
#include "identify/pose_measurements.hpp"
#include "robot/pose_fit.hpp"
#include "robot/robot_model.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;

// "Q1,Q2,Q3:path" -> the pose and the FRF (a freq_hz,re_m_per_n,im_m_per_n[,coherence] receptance CSV).
robot::MeasuredFrf measured_frf(const std::string& item) {
  const auto colon = item.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument("--measured = '" + item + "': expected Q1,Q2,...:FRF.csv (joint angles in deg)");
  robot::MeasuredFrf m;
  std::stringstream qs(item.substr(0, colon));
  for (std::string tok; std::getline(qs, tok, ',');) {
    double v = 0.0;
    if (auto p = parse_number("--measured", tok, {"deg", -360.0, 360.0}, false, v))
      throw std::invalid_argument(*p + " (in '" + item + "')");
    m.joints_deg.push_back(v);
  }
  m.name = item.substr(colon + 1);
  const identify::FrfData d = identify::read_frf_csv(m.name, identify::FrfKind::kReceptance);
  m.freq_hz = d.f_hz;
  m.receptance_m_per_n = d.h;
  return m;
}

struct FitData {
  std::vector<robot::MeasuredFrf> fit, held;
  std::optional<robot::FrfDirection> direction;  // from the measurements' configuration
  int modes{0};                                  // its pose_schedule.modes
};

// --measured items and --measurements directories (checked against the model: identify::check_against_model),
// the --hold-out poses set apart.
FitData fit_data(const PoseArgs& a, const config::RobotModelConfig& model) {
  FitData d;
  for (const auto& item : a.measured) d.fit.push_back(measured_frf(item));
  if (!a.measurements.empty()) {
    identify::PoseMeasurements pm = identify::read_pose_measurements(a.measurements);
    identify::check_against_model(pm, model);
    d.direction = pm.direction;
    d.modes = pm.modes;
    for (auto& f : pm.frfs) d.fit.push_back(std::move(f));
  }
  for (const auto& name : a.hold_out) {
    const auto it = std::find_if(d.fit.begin(), d.fit.end(), [&](const auto& f) { return f.name == name; });
    if (it == d.fit.end()) throw std::invalid_argument("--hold-out '" + name + "': no measured pose of that name");
    d.held.push_back(std::move(*it));
    d.fit.erase(it);
  }
  if (d.fit.empty())
    throw std::invalid_argument(
        "robodamp pose fit: give --measured Q1,Q2,...:FRF.csv or --measurements DIR, and keep at "
        "least one pose in the fit");
  return d;
}

robot::PoseFitSettings fit_settings(const PoseArgs& a, const FitData& d) {
  robot::PoseFitSettings s;
  s.direction = a.direction == "xx"   ? robot::FrfDirection::kXX
                : a.direction == "xy" ? robot::FrfDirection::kXY
                                      : robot::FrfDirection::kYY;
  if (d.direction) s.direction = *d.direction;
  s.band_min_hz = a.fit_band_hz[0], s.band_max_hz = a.fit_band_hz[1];
  s.modes = a.fit_modes.value_or(d.modes);
  s.restarts = a.restarts;
  s.pso.particles = a.particles, s.pso.iterations = a.iterations, s.pso.seed = static_cast<std::uint64_t>(a.seed);
  return s;
}

// Each pose: its role, the model's error before and after the fit, the receptance's peak frequency.
json pose_rows(const config::RobotModelConfig& nominal, const config::RobotModelConfig& fitted,
               const std::vector<robot::MeasuredFrf>& data, const robot::PoseFitSettings& s, const char* role,
               std::ostringstream& t) {
  json rows = json::array();
  if (data.empty()) return rows;
  const std::vector<double> before = robot::model_errors(nominal, data, s),
                            after = robot::model_errors(fitted, data, s);
  const std::vector<double> f_data = robot::peak_hz(nullptr, data, s), f_before = robot::peak_hz(&nominal, data, s),
                            f_after = robot::peak_hz(&fitted, data, s);
  char b[240];
  for (std::size_t p = 0; p < data.size(); ++p) {
    std::snprintf(b, sizeof b, "  %-10s %-30s %-9s %9.2f %9.2f   %8.2f %8.2f %8.2f\n", data[p].name.c_str(),
                  config::describe_pose(data[p].joints_deg).c_str(), role, 100.0 * before[p], 100.0 * after[p],
                  f_data[p], f_before[p], f_after[p]);
    t << b;
    rows.push_back({{"frf", data[p].name},
                    {"joints_deg", data[p].joints_deg},
                    {"role", role},
                    {"nominal_error_pct", 100.0 * before[p]},
                    {"error_pct", 100.0 * after[p]},
                    {"peak_hz", f_data[p]},
                    {"nominal_peak_hz", f_before[p]},
                    {"fitted_peak_hz", f_after[p]}});
  }
  return rows;
}

}  // namespace

int run_fit(const config::RobotModelConfig& m, const PoseArgs& a) {
  const FitData d = fit_data(a, m);
  const robot::PoseFitSettings s = fit_settings(a, d);
  const robot::PoseFitResult r = robot::fit_joints(m, d.fit, s);
  const char* dir = s.direction == robot::FrfDirection::kXX   ? "xx"
                    : s.direction == robot::FrfDirection::kXY ? "xy"
                                                              : "yy";
  std::ostringstream t;
  char b[240];
  const std::string form = s.modes > 0 ? "its " + std::to_string(s.modes) + " lowest modes" : "its own receptance";
  std::snprintf(b, sizeof b,
                "robot %s (as %s) fitted to %zu FRF(s) (%s, %g-%g Hz): %d evaluations, %d of %d restarts converged\n",
                m.name.c_str(), form.c_str(), d.fit.size(), dir, s.band_min_hz, s.band_max_hz, r.evaluations,
                r.converged_restarts, s.restarts);
  t << b << "  joint   stiffness N m/rad   spread %   damping ratio\n";
  json joints = json::array();
  for (std::size_t j = 0; j < r.stiffness_nm_per_rad.size(); ++j) {
    std::snprintf(b, sizeof b, "  %5zu   %17.5g   %8.3f   %13.4f\n", j + 1, r.stiffness_nm_per_rad[j],
                  r.stiffness_spread_pct[j], r.damping_ratio[j]);
    t << b;
    joints.push_back({{"stiffness_nm_per_rad", r.stiffness_nm_per_rad[j]},
                      {"spread_pct", r.stiffness_spread_pct[j]},
                      {"damping_ratio", r.damping_ratio[j]}});
  }
  t << "  the TCP receptance against the model file as given (nominal) and fitted: the weighted relative error and\n"
       "  the frequency of the largest receptance in the band\n";
  std::snprintf(b, sizeof b, "  %-10s %-30s %-9s %19s   %26s\n  %-10s %-30s %-9s %9s %9s   %8s %8s %8s\n", "", "", "",
                "error %", "peak Hz", "pose", "joints", "role", "nominal", "fitted", "measured", "nominal", "fitted");
  t << b;
  json poses = pose_rows(m, r.fitted, d.fit, s, "fit", t);
  for (auto& row : pose_rows(m, r.fitted, d.held, s, "held out", t)) poses.push_back(std::move(row));
  const json out = {{"model", m.source},
                    {"direction", dir},
                    {"modes", s.modes},
                    {"joints", joints},
                    {"poses", poses},
                    {"restart_costs", r.restart_costs},
                    {"evaluations", r.evaluations},
                    {"converged_restarts", r.converged_restarts}};
  if (!a.out_path.empty()) {
    std::ofstream f(a.out_path);
    f << config::robot_model_yaml(r.fitted);
    if (!f) {
      std::cerr << "--out " << a.out_path << ": cannot write\n";
      return 1;
    }
    t << "  wrote the fitted model to " << a.out_path << '\n';
  }
  if (!also_json_out(a, out)) return 1;
  return print_report(out.dump(2), a.json, "pose", t.str(), "", {}, "");
}

bool also_json_out(const PoseArgs& a, const nlohmann::json& j) {
  if (a.json_out_path.empty()) return true;
  return emit_json(JsonOut{a.json_out_path, true}, j.dump(2), "pose");
}

}  // namespace robodamp::apps
