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
#include "robot/pose_report.hpp"
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

}  // namespace

int run_fit(const config::RobotModelConfig& m, const PoseArgs& a) {
  const FitData d = fit_data(a, m);
  const robot::PoseFitSettings s = fit_settings(a, d);
  const robot::PoseFitResult r = robot::fit_joints(m, d.fit, s);
  robot::PoseReport report = robot::pose_fit_report(m, r, d.fit, d.held, s);
  if (!a.out_path.empty()) {
    std::ofstream f(a.out_path);
    f << config::robot_model_yaml(r.fitted);
    if (!f) {
      std::cerr << "--out " << a.out_path << ": cannot write\n";
      return 1;
    }
    report.text += "  wrote the fitted model to " + a.out_path + '\n';
  }
  if (!also_json_out(a, report.json)) return 1;
  return print_report(report.json.dump(2), a.json, "pose", report.text, "", {}, "");
}

bool also_json_out(const PoseArgs& a, const nlohmann::json& j) {
  if (a.json_out_path.empty()) return true;
  return emit_json(JsonOut{a.json_out_path, true}, j.dump(2), "pose");
}

}  // namespace robodamp::apps
