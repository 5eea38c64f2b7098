#include "config/pose_schedule_config.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "config/config.hpp"
#include "config/file_paths.hpp"
#include "config/robot_model_config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

bool region_holds(const PoseRegionConfig& r, const double* q, std::size_t n) {
  if (n != r.min_deg.size()) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (!(q[i] >= r.min_deg[i] && q[i] <= r.max_deg[i])) return false;  // NaN fails
  return true;
}

std::optional<std::size_t> region_of(const PoseScheduleConfig& s, const double* q, std::size_t n,
                                     std::optional<std::size_t> current) {
  if (n != s.joints()) return std::nullopt;
  for (std::size_t i = 0; i < n; ++i)
    if (!(q[i] >= s.workspace_min_deg[i] && q[i] <= s.workspace_max_deg[i])) return std::nullopt;
  if (current && *current < s.regions.size() && region_holds(s.regions[*current], q, n)) return current;
  for (std::size_t r = 0; r < s.regions.size(); ++r)
    if (region_holds(s.regions[r], q, n)) return r;
  return std::nullopt;
}

std::optional<std::vector<double>> uncovered_pose(const PoseScheduleConfig& s) {
  const std::size_t n = s.joints();
  // Per joint, the workspace cut at every region face inside it; a cell's midpoint stands for the cell.
  std::vector<std::vector<double>> mids(n);
  for (std::size_t j = 0; j < n; ++j) {
    std::vector<double> cuts{s.workspace_min_deg[j], s.workspace_max_deg[j]};
    for (const auto& r : s.regions)
      for (double v : {r.min_deg[j], r.max_deg[j]})
        if (v > s.workspace_min_deg[j] && v < s.workspace_max_deg[j]) cuts.push_back(v);
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) mids[j].push_back(0.5 * (cuts[k] + cuts[k + 1]));
    if (cuts.size() == 1) mids[j].push_back(cuts[0]);
  }
  std::vector<std::size_t> idx(n, 0);
  std::vector<double> q(n);
  for (;;) {
    for (std::size_t j = 0; j < n; ++j) q[j] = mids[j][idx[j]];
    if (!region_of(s, q.data(), n)) return q;
    std::size_t j = 0;
    while (j < n && ++idx[j] == mids[j].size()) idx[j++] = 0;
    if (j == n) return std::nullopt;
  }
}

std::string describe_pose(const std::vector<double>& q) {
  std::string s = "[";
  for (std::size_t i = 0; i < q.size(); ++i) s += (i ? ", " : "") + format_number(q[i]);
  return s + "] deg";
}

namespace detail {

namespace {

void check_box(MapReader& r, const std::string& what, const std::vector<double>& lo, const std::vector<double>& hi,
               const RobotModelConfig* model) {
  if (lo.size() != hi.size()) {
    r.diagnostics().add(r.mark(), r.path_of(what + "max_deg"),
                        "has " + std::to_string(hi.size()) + " angles for " + std::to_string(lo.size()) + " in " +
                            what + "min_deg: one per joint");
    return;
  }
  if (model && lo.size() != model->joints.size())
    r.diagnostics().add(r.mark(), r.path_of(what + "min_deg"),
                        "has " + std::to_string(lo.size()) + " angles; the robot model " + model->source + " has " +
                            std::to_string(model->joints.size()) + " joints");
  for (std::size_t i = 0; i < lo.size(); ++i) {
    if (!(lo[i] <= hi[i]))
      r.diagnostics().add(
          r.mark(), r.path_of(what + "max_deg") + "[" + std::to_string(i) + "]",
          "= " + format_number(hi[i]) + " deg is below " + what + "min_deg = " + format_number(lo[i]) + " deg");
    if (model && i < model->joints.size()) {
      const auto& j = model->joints[i];
      for (const auto& [key, v] : {std::pair{what + "min_deg", lo[i]}, std::pair{what + "max_deg", hi[i]}})
        if (auto p = range_problem(r.path_of(key) + "[" + std::to_string(i) + "]", v,
                                   {"deg", j.min_deg, j.max_deg, false, false,
                                    "joint " + std::to_string(i + 1) + "'s travel in " + model->source}))
          r.diagnostics().add(r.mark(), r.path_of(key) + "[" + std::to_string(i) + "]", *p);
    }
  }
}

// compensator: {numerator: [...], denominator: [...]}: proper, finite, a leading denominator coefficient
// and every denominator coefficient positive (necessary for a stable compensator).
std::optional<RegionCompensatorConfig> read_region_compensator(MapReader& region) {
  const YAML::Node n = region.child("compensator", false, "");
  if (!present(n)) return std::nullopt;
  MapReader r(region.diagnostics(), n, region.path_of("compensator"), region.mark());
  RegionCompensatorConfig c;
  const auto num = r.number_list("numerator", "coefficients of s, highest power first");
  const auto den = r.number_list("denominator", "coefficients of s, highest power first");
  r.finish();
  if (!num || !den) return std::nullopt;
  c.numerator = *num, c.denominator = *den;
  const std::size_t before = region.diagnostics().problems().size();
  auto refuse = [&](const std::string& key, const std::string& why) {
    region.diagnostics().add(r.mark(), r.path_of(key), why);
  };
  if (c.numerator.empty() || c.denominator.empty())
    refuse("denominator", "and numerator must not be empty");
  else if (c.numerator.size() > c.denominator.size())
    refuse("numerator", "has " + std::to_string(c.numerator.size()) + " coefficients, more than the denominator's " +
                            std::to_string(c.denominator.size()) + ": the compensator must be proper");
  for (std::size_t i = 0; i < c.numerator.size(); ++i)
    if (!std::isfinite(c.numerator[i])) refuse("numerator[" + std::to_string(i) + "]", "is not a finite number");
  for (std::size_t i = 0; i < c.denominator.size(); ++i)
    if (!(c.denominator[i] > 0.0) || !std::isfinite(c.denominator[i]))
      refuse("denominator[" + std::to_string(i) + "]",
             "= " + format_number(c.denominator[i]) +
                 " is not allowed: every coefficient must be positive and finite "
                 "(a stable, minimum-phase compensator, as robodamp pose tune writes)");
  if (region.diagnostics().problems().size() != before) return std::nullopt;
  return c;
}

PoseRegionConfig read_region(Diagnostics& d, const YAML::Node& n, const std::string& key,
                             const RobotModelConfig* model) {
  MapReader r(d, n, key, n.Mark());
  PoseRegionConfig c;
  c.name = r.text("name", std::nullopt).value_or(key);
  if (auto v = r.number_list("min_deg", "deg")) c.min_deg = *v;
  if (auto v = r.number_list("max_deg", "deg")) c.max_deg = *v;
  if (present(r.child("gain_ns_per_m", false, "")))  // optional: default controller.gain_ns_per_m
    if (auto v = r.number("gain_ns_per_m", {"N s/m", 0.0, 1e6})) c.gain_ns_per_m = *v;
  if (present(r.child("polarity", false, "")))
    if (auto v = read_sign(r, "polarity", 1)) c.polarity = *v;
  if (present(r.child("match_freq_hz", false, "")))
    if (auto v = r.number("match_freq_hz", {"Hz", 0.0, 1e4, true})) c.match_freq_hz = *v;
  c.compensator = read_region_compensator(r);
  check_box(r, "", c.min_deg, c.max_deg, model);
  r.finish();
  return c;
}

}  // namespace

std::optional<PoseScheduleConfig> read_pose_schedule(MapReader& top, const std::string& source) {
  const YAML::Node node = top.child("pose_schedule", false, "");
  if (!present(node)) return std::nullopt;
  Diagnostics& d = top.diagnostics();
  MapReader r(d, node, "pose_schedule", top.mark());
  PoseScheduleConfig c;
  std::optional<RobotModelConfig> model;
  if (auto v = r.text("model", std::nullopt))
    model = read_robot_model_file(r, "pose_schedule.model", source, *v, c.model, c.model_resolved);
  if (auto v = r.choice("axis", {"x", "y"}, "y")) c.axis = *v == "x" ? 0 : 1;
  if (auto v = read_int(r, "modes", {"(modes)", 1, 12}, c.modes)) c.modes = *v;
  if (auto v = read_int(r, "grid_points", {"(points per joint)", 2, 9}, c.grid_points)) c.grid_points = *v;
  const Range band{"Hz", 0.0, 1e4, false, false, "the robot's modes lie far below"};
  if (auto v = r.number("damping_band_min_hz", band, c.damping_band_min_hz)) c.damping_band_min_hz = *v;
  if (auto v = r.number("damping_band_max_hz", band, c.damping_band_max_hz)) c.damping_band_max_hz = *v;
  if (c.damping_band_max_hz <= c.damping_band_min_hz)
    d.add(r.mark(), "pose_schedule.damping_band_max_hz",
          "= " + format_number(c.damping_band_max_hz) +
              " Hz must be above pose_schedule.damping_band_min_hz = " + format_number(c.damping_band_min_hz) + " Hz");
  const YAML::Node ws = r.child("workspace", true, "the joint-angle box the robot works in: min_deg, max_deg");
  if (present(ws)) {
    MapReader w(d, ws, "pose_schedule.workspace", r.mark());
    if (auto v = w.number_list("min_deg", "deg")) c.workspace_min_deg = *v;
    if (auto v = w.number_list("max_deg", "deg")) c.workspace_max_deg = *v;
    check_box(w, "", c.workspace_min_deg, c.workspace_max_deg, model ? &*model : nullptr);
    w.finish();
  }
  const YAML::Node regions = r.child("regions", true, "a list of joint-angle boxes, each with its parameter set");
  if (present(regions) && (!regions.IsSequence() || regions.size() == 0))
    d.add(regions.Mark(), "pose_schedule.regions", "must be a non-empty list of regions (name, min_deg, max_deg)");
  for (std::size_t i = 0; regions.IsSequence() && i < regions.size(); ++i)
    c.regions.push_back(
        read_region(d, regions[i], "pose_schedule.regions[" + std::to_string(i) + "]", model ? &*model : nullptr));
  r.finish();
  const std::size_t n = c.workspace_min_deg.size();
  const bool shapes_ok = n > 0 && c.workspace_max_deg.size() == n && !c.regions.empty() &&
                         std::all_of(c.regions.begin(), c.regions.end(), [n](const PoseRegionConfig& g) {
                           return g.min_deg.size() == n && g.max_deg.size() == n;
                         });
  if (shapes_ok) {
    for (std::size_t i = 0; i < c.regions.size(); ++i)
      for (std::size_t k = 0; k < i; ++k)
        if (c.regions[i].name == c.regions[k].name)
          d.add(r.mark(), "pose_schedule.regions[" + std::to_string(i) + "].name",
                "= '" + c.regions[i].name + "' names regions[" + std::to_string(k) + "] too: names must be unique");
    if (auto hole = uncovered_pose(c))
      d.add(r.mark(), "pose_schedule.regions",
            "leave a hole in the workspace: no region holds the pose " + describe_pose(*hole) +
                " (every pose of pose_schedule.workspace needs a region; outside them the controller disarms)");
  }
  return c;
}

}  // namespace detail
}  // namespace robodamp::config
