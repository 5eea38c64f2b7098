#include "config/milling_config.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "config/file_paths.hpp"
#include "config/robot_model_config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::Diagnostics;
using detail::format_number;
using detail::MapReader;
using detail::present;
using detail::Range;
using detail::read_int;
using detail::read_mode;

const char* to_string(ToolKind kind) { return kind == ToolKind::kEndMill ? "end_mill" : "ball_end"; }
const char* to_string(MillingMode mode) { return mode == MillingMode::kDown ? "down" : "up"; }
const char* to_string(Axis axis) { return axis == Axis::kX ? "x" : "y"; }

const StructureConfig* MillingConfig::find_structure(const std::string& name) const {
  for (const auto& s : structures)
    if (s.name == name) return &s;
  return nullptr;
}

const StructureConfig& MillingConfig::selected_structure() const {
  const StructureConfig* s = find_structure(structure);
  if (s == nullptr) throw ConfigError({Problem{source, {}, "structure", "no such structure: " + structure}});
  return *s;
}

namespace {

constexpr std::array<const char*, 4> kPairs{"xx", "xy", "yx", "yy"};
const Range kModeFrequency{"Hz", 0.0, 100000.0, true, false};
const Range kRpm{"rpm", 0.0, 200000.0, true, false};
const Range kCoefficient{"N/mm^2", 0.0, 100000.0, false, false};
const Range kEdge{"N/mm", 0.0, 10000.0, false, false};
const Range kOffset{"mm", -10.0, 10.0};

Axis axis_from(const std::string& s) { return s == "x" ? Axis::kX : Axis::kY; }

ToolConfig read_tool(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("tool", true, "map with kind, diameter_mm, teeth, helix_deg"), "tool",
              top.mark());
  ToolConfig t;
  if (auto v = r.choice("kind", {"end_mill", "ball_end"}, "end_mill"))
    t.kind = *v == "end_mill" ? ToolKind::kEndMill : ToolKind::kBallEnd;
  if (auto v = r.number("diameter_mm", {"mm", 0.0, 200.0, true, false})) t.diameter_mm = *v;
  if (auto v = read_int(r, "teeth", {"(teeth)", 1, 32})) t.teeth = *v;
  if (auto v = r.number("helix_deg", {"deg", 0.0, 70.0, false, false}, 30.0)) t.helix_deg = *v;
  if (auto v = r.number("flute_length_mm", {"mm", 0.0, 500.0, true, false}, 100.0)) t.flute_length_mm = *v;
  r.finish();
  return t;
}

// Exactly one spelling of each coefficient: kt or ktc, kn or krc, kte, kne or kre.
std::optional<double> one_of(MapReader& r, const std::string& a, const std::string& b, const Range& range,
                             std::optional<double> def) {
  const bool has_a = present(r.child(a, false, "")), has_b = present(r.child(b, false, ""));
  if (has_a && has_b) {
    r.diagnostics().add(r.mark(), r.path_of(b), "given together with " + a + ": the same coefficient, give one");
    return std::nullopt;
  }
  if (!has_a && !has_b && !def) {
    r.diagnostics().add(r.mark(), r.path_of(a),
                        "missing (required: " + a + " or " + b + ", " + std::string(range.unit) + ")");
    return std::nullopt;
  }
  return r.number(has_b ? b : a, range, def);
}

MaterialConfig read_material(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("material", true, "map with the cutting coefficients"), "material",
              top.mark());
  MaterialConfig m;
  m.name = r.text("name", "material").value_or("");
  if (auto v = one_of(r, "kt_n_per_mm2", "ktc_n_per_mm2", {"N/mm^2", 0.0, 100000.0, true, false}, std::nullopt))
    m.kt_n_per_mm2 = *v;
  if (auto v = one_of(r, "kn_n_per_mm2", "krc_n_per_mm2", kCoefficient, std::nullopt)) m.kr_n_per_mm2 = *v;
  if (auto v = r.number("kte_n_per_mm", kEdge, 0.0)) m.kte_n_per_mm = *v;
  if (auto v = one_of(r, "kne_n_per_mm", "kre_n_per_mm", kEdge, 0.0)) m.kre_n_per_mm = *v;
  if (present(r.child("kac_n_per_mm2", false, ""))) m.ka_n_per_mm2 = r.number("kac_n_per_mm2", kCoefficient);
  if (auto v = r.choice("force_model", {"linear", "exponential"}, "linear"); v && *v == "exponential") {
    if (auto e = r.number("chip_exponent", {"(exponent)", 0.0, 0.9, false, false})) m.chip_exponent = *e;
    if (auto h = r.number("reference_chip_mm", {"mm", 0.0, 5.0, true, false}, 0.1)) m.reference_chip_mm = *h;
  }
  r.finish();
  return m;
}

Range radial_range(const ToolConfig& t) {
  return {"mm", 0.0,   t.diameter_mm,
          true, false, "up to tool.diameter_mm = " + format_number(t.diameter_mm) + " (slotting)"};
}

CutConfig read_cut(MapReader& top, const ToolConfig& tool) {
  MapReader r(top.diagnostics(), top.child("cut", true, "map with mode, radial_mm, axial_mm, feed_per_tooth_mm"), "cut",
              top.mark());
  CutConfig c;
  if (auto v = r.choice("mode", {"down", "up"})) c.mode = *v == "down" ? MillingMode::kDown : MillingMode::kUp;
  if (auto v = r.number("radial_mm", radial_range(tool))) c.radial_mm = *v;
  if (auto v = r.number("axial_mm", {"mm", 0.0, 100.0, true, false})) c.axial_mm = *v;
  if (auto v = r.number("feed_per_tooth_mm", {"mm", 0.0, 5.0, true, false})) c.feed_per_tooth_mm = *v;
  if (auto v = r.choice("feed_axis", {"x", "y"}, "x")) c.feed_axis = axis_from(*v);
  if (auto v = r.number("spindle_rpm", kRpm)) c.spindle_rpm = *v;
  r.finish();
  return c;
}

std::optional<ControllerPartConfig> read_controller_part(MapReader& pr, const std::string& base_dir) {
  Diagnostics& d = pr.diagnostics();
  const YAML::Node n = pr.child("controller", false, "");
  if (!present(n)) return std::nullopt;
  MapReader r(d, n, pr.path_of("controller"), pr.mark());
  ControllerPartConfig c;
  if (auto v = r.text("config", std::nullopt)) {
    const FoundFile f = find_named_file(base_dir, *v);
    c.config_path = f.path;
    if (!f.found)
      d.add(n.Mark(), r.path_of("config"), "= '" + *v + "': no such file (looked for " + f.looked_text() + ")");
  }
  if (auto v = read_int(r, "location", {"(location id)", 1, 64}, 1)) c.location = *v;
  if (auto v = r.choice("direction", {"x", "y"}, "y")) c.direction = axis_from(*v);
  r.finish();
  return c;
}

// pose: {model: FILE, joints_deg: [...]}: the model read and the pose checked against its joints' travel.
std::optional<PosePartConfig> read_pose_part(MapReader& pr, const std::string& base_dir) {
  Diagnostics& d = pr.diagnostics();
  const YAML::Node n = pr.child("pose", false, "");
  if (!present(n)) return std::nullopt;
  MapReader r(d, n, pr.path_of("pose"), pr.mark());
  PosePartConfig c;
  if (auto v = r.text("model", std::nullopt)) {
    const FoundFile f = find_named_file(base_dir, *v);
    c.model_path = f.path;
    if (!f.found) {
      d.add(n.Mark(), r.path_of("model"), "= '" + *v + "': no such file (looked for " + f.looked_text() + ")");
      c.model_path.clear();
    }
  }
  c.joints_deg = r.number_list("joints_deg", "deg").value_or(std::vector<double>{});
  r.finish();
  if (!c.model_path.empty()) {
    try {
      const RobotModelConfig m = load_robot_model(c.model_path);
      if (auto problem = pose_problem(m, c.joints_deg)) d.add(n.Mark(), r.path_of("joints_deg"), *problem);
    } catch (const ConfigError& e) {
      d.add(n.Mark(), r.path_of("model"), std::string("= '") + c.model_path + "': " + e.what());
    }
  }
  return c;
}

StructureConfig read_structure(Diagnostics& d, const YAML::Node& node, const std::string& key,
                               const std::string& base_dir) {
  MapReader r(d, node, key, node.Mark());
  StructureConfig s;
  s.name = r.text("name", std::nullopt).value_or("");
  const YAML::Node parts = r.child("parts", true, "list of FRF contributions (summed)");
  if (present(parts) && (!parts.IsSequence() || parts.size() == 0))
    d.add(parts.Mark(), key + ".parts", "must be a non-empty list");
  for (std::size_t i = 0; parts.IsSequence() && i < parts.size(); ++i) {
    const std::string pk = key + ".parts[" + std::to_string(i) + "]";
    MapReader pr(d, parts[i], pk, parts.Mark());
    StructurePartConfig p;
    p.name = pr.text("name", "part " + std::to_string(i + 1)).value_or("");
    p.controller = read_controller_part(pr, base_dir);
    p.pose = read_pose_part(pr, base_dir);
    bool any = p.controller.has_value() || p.pose.has_value();
    for (std::size_t k = 0; k < kPairs.size(); ++k) {
      const YAML::Node modes = pr.child(kPairs[k], false, "");
      if (!present(modes)) continue;
      any = true;
      if (!modes.IsSequence() || modes.size() == 0) {
        d.add(modes.Mark().is_null() ? pr.mark() : modes.Mark(), pr.path_of(kPairs[k]),
              "must be a non-empty list of modes");
        continue;
      }
      for (std::size_t m = 0; m < modes.size(); ++m) {
        MapReader mr(d, modes[m], pr.path_of(kPairs[k]) + "[" + std::to_string(m) + "]", modes.Mark());
        p.modes[k].push_back(read_mode(mr, kModeFrequency));
      }
    }
    if (!any)
      d.add(parts[i].Mark(), pk, "has no FRF: give modes under xx, xy, yx, yy, a controller location or a robot pose");
    pr.finish();
    s.parts.push_back(std::move(p));
  }
  r.finish();
  return s;
}

// rpm_min < rpm_max of a section.
void read_speed_range(MapReader& r, double& rpm_min, double& rpm_max) {
  if (auto v = r.number("rpm_min", kRpm, rpm_min)) rpm_min = *v;
  if (auto v = r.number("rpm_max", kRpm, rpm_max)) rpm_max = *v;
  if (rpm_max <= rpm_min)
    r.diagnostics().add(r.mark(), r.path_of("rpm_max"),
                        "= " + format_number(rpm_max) + " rpm must exceed " + r.path_of("rpm_min") + " = " +
                            format_number(rpm_min) + " rpm");
}

LobesConfig read_lobes(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("lobes", false, ""), "lobes", top.mark());
  LobesConfig c;
  read_speed_range(r, c.rpm_min, c.rpm_max);
  if (auto v = read_int(r, "points", {"(speeds)", 10, 1000000}, c.points)) c.points = *v;
  if (auto v = r.choice("spacing", {"linear", "log"}, "linear")) c.log_spacing = *v == "log";
  if (present(r.child("freq_max_hz", false, ""))) c.freq_max_hz = r.number("freq_max_hz", kModeFrequency);
  if (auto v = read_int(r, "points_per_mode", {"(frequencies)", 8, 100000}, c.points_per_mode)) c.points_per_mode = *v;
  r.finish();
  return c;
}

SleConfig read_sle(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("sle", false, ""), "sle", top.mark());
  SleConfig c;
  read_speed_range(r, c.rpm_min, c.rpm_max);
  if (auto v = read_int(r, "points", {"(speeds)", 2, 1000000}, c.points)) c.points = *v;
  if (auto v = read_int(r, "axial_slices", {"(slices)", 1, 10000}, c.axial_slices)) c.axial_slices = *v;
  if (auto v = read_int(r, "harmonics", {"(of the tooth frequency)", 1, 10000}, c.harmonics)) c.harmonics = *v;
  if (auto v = r.number("tolerance_um", {"um", 0.0, 1000.0, true, false}, c.tolerance_um)) c.tolerance_um = *v;
  if (auto v = read_int(r, "max_iterations", {"(iterations)", 1, 1000}, c.max_iterations)) c.max_iterations = *v;
  const YAML::Node normals = r.child("surface_normals", false, "");
  if (present(normals)) {
    c.surface_normals.clear();
    bool ok = normals.IsSequence() && normals.size() > 0 && normals.size() <= 2;
    for (std::size_t i = 0; ok && i < normals.size(); ++i) {
      ok = normals[i].IsScalar() && (normals[i].Scalar() == "x" || normals[i].Scalar() == "y");
      if (ok) c.surface_normals.push_back(axis_from(normals[i].Scalar()));
    }
    if (!ok) r.diagnostics().add(normals.Mark(), "sle.surface_normals", "must be a list of x and/or y");
  }
  r.finish();
  return c;
}

TimeDomainConfig read_time_domain(MapReader& top, const ToolConfig& tool) {
  MapReader r(top.diagnostics(), top.child("time_domain", false, ""), "time_domain", top.mark());
  TimeDomainConfig c;
  if (auto v = read_int(r, "steps_per_tooth", {"(steps, 0 = automatic)", 0, 100000}, c.steps_per_tooth))
    c.steps_per_tooth = *v;
  if (auto v = read_int(r, "min_steps_per_mode_period", {"(steps)", 8, 10000}, c.min_steps_per_mode_period))
    c.min_steps_per_mode_period = *v;
  if (auto v = read_int(r, "revolutions", {"(revolutions)", 2, 100000}, c.revolutions)) c.revolutions = *v;
  if (auto v = read_int(r, "settle_revolutions", {"(revolutions)", 1, 100000}, c.settle_revolutions))
    c.settle_revolutions = *v;
  if (c.settle_revolutions >= c.revolutions)
    r.diagnostics().add(r.mark(), r.path_of("settle_revolutions"),
                        "= " + std::to_string(c.settle_revolutions) + " must be less than " + r.path_of("revolutions") +
                            " = " + std::to_string(c.revolutions) + " (statistics need revolutions after settling)");
  if (auto v = read_int(r, "axial_slices", {"(slices)", 1, 1000}, c.axial_slices)) c.axial_slices = *v;
  if (auto v = read_int(r, "sdm_steps_per_period", {"(steps)", 4, 1000}, c.sdm_steps_per_period))
    c.sdm_steps_per_period = *v;
  if (auto v = read_int(r, "sdm_points", {"(speeds)", 10, 100000}, c.sdm_points)) c.sdm_points = *v;
  const YAML::Node runout = r.child("runout_um", false, "");
  if (present(runout)) {
    bool ok = runout.IsSequence() && static_cast<int>(runout.size()) == tool.teeth;
    for (std::size_t i = 0; ok && i < runout.size(); ++i) {
      double v = 0.0;
      ok = runout[i].IsScalar() && YAML::convert<double>::decode(runout[i], v) && std::isfinite(v) &&
           std::abs(v) <= 1000.0;
      if (ok) c.runout_um.push_back(v);
    }
    if (!ok)
      r.diagnostics().add(runout.Mark(), "time_domain.runout_um",
                          "must be a list of " + std::to_string(tool.teeth) +
                              " radial offsets, one per tooth, each -1000 <= value <= 1000 um");
  }
  const YAML::Node pitch = r.child("pitch_deg", false, "");
  if (present(pitch)) {
    bool ok = pitch.IsSequence() && static_cast<int>(pitch.size()) == tool.teeth;
    double sum = 0.0;
    for (std::size_t i = 0; ok && i < pitch.size(); ++i) {
      double v = 0.0;
      ok =
          pitch[i].IsScalar() && YAML::convert<double>::decode(pitch[i], v) && std::isfinite(v) && v > 0.0 && v < 360.0;
      if (ok) c.pitch_deg.push_back(v), sum += v;
    }
    if (!ok || std::abs(sum - 360.0) > 1e-6)
      r.diagnostics().add(pitch.Mark(), "time_domain.pitch_deg",
                          "must be a list of " + std::to_string(tool.teeth) +
                              " angles from each tooth to the next, each 0 < value < 360 deg, summing to 360 deg");
  }
  r.finish();
  return c;
}

std::vector<ConditionConfig> read_conditions(MapReader& top, const ToolConfig& tool) {
  Diagnostics& d = top.diagnostics();
  std::vector<ConditionConfig> out;
  const YAML::Node n = top.child("conditions", false, "");
  if (!present(n)) return out;
  if (!n.IsSequence()) {
    d.add(n.Mark(), "conditions", "must be a list");
    return out;
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string key = "conditions[" + std::to_string(i) + "]";
    MapReader r(d, n[i], key, n.Mark());
    ConditionConfig c;
    c.name = r.text("name", std::to_string(i + 1)).value_or("");
    if (!names.insert(c.name).second) d.add(n[i].Mark(), key + ".name", "= '" + c.name + "' is used twice");
    if (auto v = r.number("rpm", kRpm)) c.rpm = *v;
    if (auto v = r.number("axial_mm", {"mm", 0.0, 100.0, true, false})) c.axial_mm = *v;
    if (auto v = r.number("radial_mm", radial_range(tool))) c.radial_mm = *v;
    if (auto v = r.number("feed_per_tooth_mm", {"mm", 0.0, 5.0, true, false})) c.feed_per_tooth_mm = *v;
    if (auto v = r.number("path_offset_x_mm", kOffset, 0.0)) c.path_offset_x_mm = *v;
    if (auto v = r.number("path_offset_y_mm", kOffset, 0.0)) c.path_offset_y_mm = *v;
    r.finish();
    out.push_back(c);
  }
  return out;
}

}  // namespace

MillingConfig parse_milling_config(const std::string& yaml_text, const std::string& source_name,
                                   const std::string& base_dir) {
  Diagnostics d(source_name);
  const YAML::Node root = detail::load_top_map(d, yaml_text, "tool, material, cut, structures");
  MillingConfig c;
  c.source = source_name;
  MapReader top(d, root, "", root.Mark());
  c.tool = read_tool(top);
  c.material = read_material(top);
  c.cut = read_cut(top, c.tool);
  const YAML::Node structures = top.child("structures", true, "list of named structures (FRFs at the tool tip)");
  if (present(structures) && (!structures.IsSequence() || structures.size() == 0))
    d.add(structures.Mark(), "structures", "must be a non-empty list");
  std::set<std::string> names;
  for (std::size_t i = 0; structures.IsSequence() && i < structures.size(); ++i) {
    const std::string key = "structures[" + std::to_string(i) + "]";
    c.structures.push_back(read_structure(d, structures[i], key, base_dir));
    if (!names.insert(c.structures.back().name).second)
      d.add(structures[i].Mark(), key + ".name", "= '" + c.structures.back().name + "' is used twice");
  }
  const std::string first = c.structures.empty() ? std::string() : c.structures.front().name;
  c.structure = top.text("structure", first.empty() ? std::optional<std::string>() : first).value_or("");
  if (!c.structures.empty() && c.find_structure(c.structure) == nullptr) {
    std::string known;
    for (const auto& s : c.structures) known += (known.empty() ? "" : ", ") + s.name;
    d.add(top.mark(), "structure", "= '" + c.structure + "' is not one of the structures: " + known);
  }
  c.lobes = read_lobes(top);
  c.sle = read_sle(top);
  c.time_domain = read_time_domain(top, c.tool);
  c.conditions = read_conditions(top, c.tool);
  top.finish();
  if (!d.problems().empty()) throw ConfigError(located(d.problems(), yaml_text));
  return c;
}

MillingConfig load_milling_config(const std::string& path) {
  return parse_milling_config(detail::read_config_text(path), path, std::filesystem::path(path).parent_path().string());
}

}  // namespace robodamp::config
