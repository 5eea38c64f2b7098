// `robodamp pose fit`: the robot model's joints fitted to measured TCP receptances (robot/pose_fit.hpp), the
// error before and after at each pose, the held-out poses apart.
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/pose_command.hpp"
#include "identify/pose_fit_inputs.hpp"
#include "robot/pose_fit.hpp"
#include "robot/pose_report.hpp"
#include "robot/robot_model.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;

robot::PoseFitSettings fit_settings(const PoseArgs& a, const identify::PoseFitInputs& d) {
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
  const identify::PoseFitInputs d = identify::read_pose_fit_inputs(a.measured, a.measurements, a.hold_out, m);
  if (d.fit.empty())
    throw std::invalid_argument(
        "robodamp pose fit: give --measured Q1,Q2,...:FRF.csv or --measurements DIR, and keep at "
        "least one pose in the fit");
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
