#include "config/robot_model_config.hpp"

#include <algorithm>

#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::Diagnostics;
using detail::MapReader;
using detail::present;

namespace {

RobotLinkConfig read_link(MapReader& r) {
  RobotLinkConfig c;
  if (auto v = r.number("length_m", {"m", 0.0, 20.0, true})) c.length_m = *v;
  if (auto v = r.number("mass_kg", {"kg", 0.0, 1e4, true})) c.mass_kg = *v;
  if (auto v = r.number("bending_stiffness_nm2", {"N m^2", 0.0, 1e12, true})) c.bending_stiffness_nm2 = *v;
  if (auto v = r.number("axial_stiffness_n", {"N", 0.0, 1e13, true}, 1e10)) c.axial_stiffness_n = *v;
  if (auto v = detail::read_int(r, "elements", {"(elements)", 1, 64}, 4)) c.elements = *v;
  return c;
}

RobotJointConfig read_joint(MapReader& r) {
  RobotJointConfig c;
  if (auto v = r.number("stiffness_nm_per_rad", {"N m/rad", 0.0, 1e10, true})) c.stiffness_nm_per_rad = *v;
  if (auto v = r.number("damping_ratio", {"", 0.0, 1.0, false, true}, 0.02)) c.damping_ratio = *v;
  if (auto v = r.number("min_deg", {"deg", -360.0, 360.0}, -180.0)) c.min_deg = *v;
  if (auto v = r.number("max_deg", {"deg", -360.0, 360.0}, 180.0)) c.max_deg = *v;
  if (auto v = r.number("translational_stiffness_n_per_m", {"N/m", 0.0, 1e13}, 0.0))
    c.translational_stiffness_n_per_m = *v;
  if (c.min_deg >= c.max_deg)
    r.diagnostics().add(
        r.mark(), r.path_of("max_deg"),
        "= " + format_number(c.max_deg) + " deg must be above min_deg = " + format_number(c.min_deg) + " deg");
  return c;
}

template <typename Item, typename Read>
std::vector<Item> read_list(Diagnostics& d, MapReader& top, const std::string& key, const char* what, Read read) {
  const YAML::Node n = top.child(key, true, what);
  std::vector<Item> out;
  if (present(n) && (!n.IsSequence() || n.size() == 0)) d.add(n.Mark(), key, "must be a non-empty list");
  for (std::size_t i = 0; n.IsSequence() && i < n.size(); ++i) {
    MapReader r(d, n[i], key + "[" + std::to_string(i) + "]", n.Mark());
    out.push_back(read(r));
    r.finish();
  }
  return out;
}

}  // namespace

std::optional<std::string> pose_problem(const RobotModelConfig& m, const std::vector<double>& q) {
  if (q.size() != m.joints.size())
    return "a pose needs " + std::to_string(m.joints.size()) + " joint angles (deg), got " + std::to_string(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    const auto& j = m.joints[i];
    if (auto p = range_problem("joint " + std::to_string(i + 1), q[i],
                               {"deg", j.min_deg, j.max_deg, false, false, "the joint's travel in " + m.source}))
      return p;
  }
  return std::nullopt;
}

namespace {

// The poses: list, each checked against the model's joints (when it has them).
std::vector<RobotPoseConfig> read_poses(Diagnostics& d, MapReader& top, const RobotModelConfig& model, bool required) {
  std::vector<RobotPoseConfig> out;
  const YAML::Node poses = top.child("poses", required, "the poses, each {name, joints_deg: [one angle per joint]}");
  for (std::size_t i = 0; poses.IsSequence() && i < poses.size(); ++i) {
    const std::string key = "poses[" + std::to_string(i) + "]";
    MapReader r(d, poses[i], key, poses.Mark());
    RobotPoseConfig p;
    p.name = r.text("name", "pose " + std::to_string(i + 1)).value_or("");
    p.joints_deg = r.number_list("joints_deg", "deg").value_or(std::vector<double>{});
    p.measured_f1_hz = r.number("measured_f1_hz", {"Hz", 0.0, 1e4, true}, 0.0);
    p.predicted_f1_hz = r.number("predicted_f1_hz", {"Hz", 0.0, 1e4, true}, 0.0);
    if (p.measured_f1_hz == 0.0) p.measured_f1_hz.reset();
    if (p.predicted_f1_hz == 0.0) p.predicted_f1_hz.reset();
    r.finish();
    if (!model.joints.empty())
      if (auto problem = pose_problem(model, p.joints_deg)) d.add(poses[i].Mark(), key + ".joints_deg", *problem);
    out.push_back(std::move(p));
  }
  if (required && present(poses) && out.empty()) d.add(top.mark(), "poses", "is empty: list at least one pose");
  return out;
}

// measured_modes: {axis: x|y, poses: [{name, joints_deg, modes: [{natural_freq_hz, damping_ratio,
// stiffness_n_per_m}, ...]}, ...]}, each pose checked against the joints.
std::optional<MeasuredModesConfig> read_measured_modes(Diagnostics& d, MapReader& top, const RobotModelConfig& model) {
  const YAML::Node n = top.child("measured_modes", false, "");
  if (!present(n)) return std::nullopt;
  MapReader r(d, n, "measured_modes", top.mark());
  MeasuredModesConfig c;
  if (auto v = r.choice("axis", {"x", "y"}, "y")) c.axis = *v == "x" ? 0 : 1;
  const YAML::Node poses = r.child("poses", true, "the measured poses, each {name, joints_deg, modes}");
  if (present(poses) && (!poses.IsSequence() || poses.size() == 0))
    d.add(poses.Mark(), "measured_modes.poses", "must be a non-empty list");
  for (std::size_t i = 0; poses.IsSequence() && i < poses.size(); ++i) {
    const std::string key = "measured_modes.poses[" + std::to_string(i) + "]";
    MapReader pr(d, poses[i], key, poses.Mark());
    MeasuredPoseModes p;
    p.name = pr.text("name", "pose " + std::to_string(i + 1)).value_or("");
    p.joints_deg = pr.number_list("joints_deg", "deg").value_or(std::vector<double>{});
    if (auto problem = pose_problem(model, p.joints_deg)) d.add(poses[i].Mark(), key + ".joints_deg", *problem);
    const YAML::Node modes = pr.child("modes", true, "the modes identified there, lowest first");
    if (present(modes) && (!modes.IsSequence() || modes.size() == 0))
      d.add(poses[i].Mark(), key + ".modes", "must be a non-empty list");
    for (std::size_t k = 0; modes.IsSequence() && k < modes.size(); ++k) {
      MapReader mr(d, modes[k], key + ".modes[" + std::to_string(k) + "]", modes.Mark());
      ModeConfig m;
      m.form = ModeForm::kStiffness;
      if (auto v = mr.number("natural_freq_hz", {"Hz", 0.0, 1e4, true})) m.natural_freq_hz = *v;
      if (auto v = mr.number("damping_ratio", {"", 0.0, 1.0, true, true})) m.damping_ratio = *v;
      if (auto v = mr.number("stiffness_n_per_m", {"N/m", 0.0, 1e13, true})) m.stiffness_n_per_m = *v;
      mr.finish();
      p.modes.push_back(m);
    }
    pr.finish();
    c.poses.push_back(std::move(p));
  }
  r.finish();
  return c;
}

}  // namespace

RobotModelConfig parse_robot_model(const std::string& yaml_text, const std::string& source_name) {
  Diagnostics d(source_name);
  const YAML::Node root = detail::load_top_map(d, yaml_text, "name, links, joints, head, poses");
  RobotModelConfig c;
  c.source = source_name;
  MapReader top(d, root, "", root.Mark());
  c.name = top.text("name", "robot").value_or("robot");
  c.links = read_list<RobotLinkConfig>(d, top, "links", "the links from the base, each a map", read_link);
  c.joints = read_list<RobotJointConfig>(d, top, "joints", "one joint per link, from the base", read_joint);
  if (!c.links.empty() && c.joints.size() != c.links.size())
    d.add(top.mark(), "joints",
          "has " + std::to_string(c.joints.size()) + " entries for " + std::to_string(c.links.size()) +
              " links: one joint drives each link");
  const YAML::Node head = top.child("head", false, "");
  if (present(head)) {
    MapReader h(d, head, "head", top.mark());
    if (auto v = h.number("mass_kg", {"kg", 0.0, 1e4}, 0.0)) c.head_mass_kg = *v;
    if (auto v = h.number("inertia_kgm2", {"kg m^2", 0.0, 1e4}, 0.0)) c.head_inertia_kgm2 = *v;
    h.finish();
  }
  c.poses = read_poses(d, top, c, false);
  if (c.joints.size() == c.links.size() && !c.joints.empty()) c.measured_modes = read_measured_modes(d, top, c);
  top.finish();
  if (!d.problems().empty()) throw ConfigError(d.problems());
  return c;
}

std::vector<RobotPoseConfig> parse_pose_list(const std::string& yaml_text, const std::string& source_name,
                                             const RobotModelConfig& model) {
  Diagnostics d(source_name);
  const YAML::Node root = detail::load_top_map(d, yaml_text, "name, links, joints, head, poses");
  MapReader top(d, root, "", root.Mark());
  std::vector<RobotPoseConfig> poses = read_poses(d, top, model, true);
  for (const char* other : {"name", "links", "joints", "head", "measured_modes"})
    (void)top.child(other, false, "");  // a model file's
  top.finish();
  std::vector<std::string> names;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (std::find(names.begin(), names.end(), poses[i].name) != names.end())
      d.add(root.Mark(), "poses[" + std::to_string(i) + "].name",
            "'" + poses[i].name + "' names two poses: each pose's measurement goes to a directory of its name");
    names.push_back(poses[i].name);
  }
  if (!d.problems().empty()) throw ConfigError(d.problems());
  return poses;
}

RobotModelConfig load_robot_model(const std::string& path) {
  return parse_robot_model(detail::read_config_text(path), path);
}

}  // namespace robodamp::config

namespace robodamp::config {

std::string robot_model_yaml(const RobotModelConfig& m) {
  std::string s = "# robodamp robot model (docs/pose_dynamics.md)\nname: " + m.name + "\nlinks:\n";
  auto n = [](double v) { return format_number(v); };
  for (const auto& l : m.links)
    s += "  - {length_m: " + n(l.length_m) + ", mass_kg: " + n(l.mass_kg) +
         ", bending_stiffness_nm2: " + n(l.bending_stiffness_nm2) + ", axial_stiffness_n: " + n(l.axial_stiffness_n) +
         ", elements: " + std::to_string(l.elements) + "}\n";
  s += "joints:\n";
  for (const auto& j : m.joints)
    s += "  - {stiffness_nm_per_rad: " + n(j.stiffness_nm_per_rad) + ", damping_ratio: " + n(j.damping_ratio) +
         ", min_deg: " + n(j.min_deg) + ", max_deg: " + n(j.max_deg) +
         (j.translational_stiffness_n_per_m > 0.0
              ? ", translational_stiffness_n_per_m: " + n(j.translational_stiffness_n_per_m)
              : "") +
         "}\n";
  s += "head: {mass_kg: " + n(m.head_mass_kg) + ", inertia_kgm2: " + n(m.head_inertia_kgm2) + "}\n";
  if (!m.poses.empty()) s += "poses:\n";
  for (const auto& p : m.poses) {
    s += "  - {name: " + p.name + ", joints_deg: [";
    for (std::size_t i = 0; i < p.joints_deg.size(); ++i) s += (i ? ", " : "") + n(p.joints_deg[i]);
    s += "]";
    if (p.measured_f1_hz) s += ", measured_f1_hz: " + n(*p.measured_f1_hz);
    if (p.predicted_f1_hz) s += ", predicted_f1_hz: " + n(*p.predicted_f1_hz);
    s += "}\n";
  }
  if (!m.measured_modes) return s;
  s += "measured_modes:  # identified at measured poses (robodamp pose modes); the model's modes are corrected towards "
       "them\n";
  s += std::string("  axis: ") + (m.measured_modes->axis == 0 ? "x" : "y") + "\n  poses:\n";
  for (const auto& p : m.measured_modes->poses) {
    s += "    - name: " + p.name + "\n      joints_deg: [";
    for (std::size_t i = 0; i < p.joints_deg.size(); ++i) s += (i ? ", " : "") + n(p.joints_deg[i]);
    s += "]\n      modes:\n";
    for (const auto& md : p.modes)
      s += "        - {natural_freq_hz: " + n(md.natural_freq_hz) + ", damping_ratio: " + n(md.damping_ratio) +
           ", stiffness_n_per_m: " + n(md.stiffness_n_per_m) + "}\n";
  }
  return s;
}

}  // namespace robodamp::config
