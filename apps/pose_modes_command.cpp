#include "apps/pose_modes_command.hpp"

#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include "identify/pose_modes_report.hpp"

namespace robodamp::apps {

namespace {

int build_map(const config::RobotModelConfig& model, const PoseModesArgs& a) {
  identify::PoseModesReport r = identify::pose_modes_map_report(model, a.measurements, a.hold_out, a.modes);
  if (!a.out_path.empty()) {
    std::ofstream f(a.out_path);
    f << config::robot_model_yaml(*r.mapped);
    if (!f) {
      std::cerr << "--out " << a.out_path << ": cannot write\n";
      return 1;
    }
    r.text += "  wrote the model with its measured modes to " + a.out_path + '\n';
  }
  return print_report(r.json.dump(2), a.json, "pose", r.text, "", {}, "");
}

std::vector<double> pose_to_show(const config::RobotModelConfig& m, const PoseModesArgs& a) {
  if (!a.joints_deg.empty()) return a.joints_deg;
  for (const auto& p : m.poses)
    if (p.name == a.pose_name) return p.joints_deg;
  if (m.measured_modes)
    for (const auto& p : m.measured_modes->poses)
      if (p.name == a.pose_name) return p.joints_deg;
  if (!a.pose_name.empty())
    throw config::ConfigError(
        {config::Problem{m.source, {}, "poses", "--pose = '" + a.pose_name + "' is not a pose the file names"}});
  if (m.poses.empty())
    throw config::ConfigError({config::Problem{m.source, {}, "poses", "give --joints (the file names no pose)"}});
  return m.poses.front().joints_deg;
}

int show_modes(const config::RobotModelConfig& model, const PoseModesArgs& a) {
  identify::require_measured_modes(model);
  const std::vector<double> q = pose_to_show(model, a);
  identify::PoseModesReport r = identify::pose_modes_at_report(model, q, a.modes);
  if (a.plot_path.empty()) return print_report(r.json.dump(2), a.json, "pose", r.text, "", {}, "");
  identify::add_pose_modes_sweep(r, model, q, a.vary_joint, a.modes);
  return print_report(
      r.json.dump(2), a.json, "pose", r.text, a.plot_path,
      [&] { return identify::plot_pose_modes_sweep(r, a.vary_joint, a.plot_path); }, a.plot_path);
}

}  // namespace

int run_pose_modes(const config::RobotModelConfig& model, const PoseModesArgs& a) {
  if (!a.measurements.empty()) return build_map(model, a);
  if (!a.out_path.empty() || !a.hold_out.empty())
    throw std::invalid_argument("pose modes: --out and --hold-out go with --measurements (the poses to map)");
  return show_modes(model, a);
}

}  // namespace robodamp::apps
