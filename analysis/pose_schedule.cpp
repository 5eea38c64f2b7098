#include "analysis/pose_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include "analysis/loop_model.hpp"
#include "analysis/mode_improvement.hpp"
#include "config/number_range.hpp"
#include "control/controller.hpp"
#include "robot/robot_model.hpp"
#include "units/units.hpp"

namespace robodamp::analysis {

namespace {

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

config::ConfigError region_error(const config::Config& cfg, std::size_t i, const std::string& message) {
  return config::ConfigError(config::located(
      {config::Problem{cfg.source, {}, "pose_schedule.regions[" + std::to_string(i) + "]", message}}, cfg.yaml_text));
}

// The modal map of a model with measured modes, built once per model, axis and count (it solves the model
// at every measured pose): pose_modes is asked thousands of times in a pose tune, from several threads.
std::shared_ptr<const robot::ModalMap> modal_map_for(const config::RobotModelConfig& model, int axis, int count) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const robot::ModalMap>> maps;
  const std::string key = config::robot_model_yaml(model) + "\n#" + std::to_string(axis) + "," + std::to_string(count);
  const std::lock_guard lock(mutex);
  auto it = maps.find(key);
  if (it != maps.end()) return it->second;
  if (maps.size() >= 16) maps.clear();  // a few models per process; a fit's trials have no measured modes
  return maps[key] = std::make_shared<const robot::ModalMap>(model, axis, count);
}

}  // namespace

double driving_point_improvement_pct(const LoopModel& m, double gain, int polarity) {
  for (const FrfResult& f : improvements(m, gain, polarity, true))
    if (f.response == m.actuator_location() && f.excitation == m.actuator_location()) return f.improvement_pct;
  return 0.0;
}

std::vector<double> region_centre(const config::PoseRegionConfig& r) {
  std::vector<double> c(r.min_deg.size());
  for (std::size_t j = 0; j < c.size(); ++j) c[j] = 0.5 * (r.min_deg[j] + r.max_deg[j]);
  return c;
}

std::vector<std::vector<double>> region_grid(const config::PoseRegionConfig& r, int points) {
  const std::size_t n = r.min_deg.size();
  std::vector<std::vector<double>> out;
  std::vector<int> idx(n, 0);
  for (;;) {
    std::vector<double> q(n);
    for (std::size_t j = 0; j < n; ++j)
      q[j] = r.min_deg[j] + (r.max_deg[j] - r.min_deg[j]) * idx[j] / static_cast<double>(points - 1);
    out.push_back(std::move(q));
    std::size_t j = 0;
    while (j < n && ++idx[j] == points) idx[j++] = 0;
    if (j == n) return out;
  }
}

PoseModes pose_modes(const config::RobotModelConfig& model, const std::vector<double>& q, int axis, int count) {
  PoseModes out;
  const std::vector<robot::AxisMode> prior = robot::axis_modes(model, q, axis, count);
  for (const robot::AxisMode& md : prior)
    out.modes.push_back(config::stiffness_mode(md.freq_hz, md.damping_ratio, md.stiffness_n_per_m));
  if (out.modes.empty())
    throw config::ConfigError({config::Problem{
        model.source,
        {},
        "pose",
        "no mode of " + model.name + " at " + config::describe_pose(q) + " moves the TCP along the axis"}});
  if (model.measured_modes) {  // the mapped modes in place of the model's (robot::ModalMap)
    const std::shared_ptr<const robot::ModalMap> map = modal_map_for(model, axis, count);
    out.corrections = map->at(q, prior);
    out.modes.clear();
    for (const robot::ModeCorrection& c : out.corrections)
      out.modes.push_back(config::stiffness_mode(c.freq_hz, c.damping_ratio, c.stiffness_n_per_m));
    out.nearest_measured_deg = map->nearest_measured_deg(q);
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < out.modes.size(); ++i)
    if (out.modes[i].stiffness_n_per_m * out.modes[i].damping_ratio < best)
      best = out.modes[i].stiffness_n_per_m * out.modes[i].damping_ratio, out.dominant = i;
  return out;
}

config::Config config_at_pose(const config::Config& base, const PoseModes& modes) {
  config::Config c = base;
  for (auto& l : c.robot.locations) l.axis_sign = 1;
  for (auto& f : c.robot.frfs) f.modes = modes.modes;
  return c;
}

config::Config config_in_plane_at_pose(const config::Config& base, const config::RobotModelConfig& model,
                                       const std::vector<double>& q, int axis, int count) {
  // The same refusals (travel, no mode along the axis); its corrections from measured modes apply in the
  // plane too: the frequency and damping as they are; the shape along the axis as the measured stiffness along
  // it says (w^2 / k), the shape across it the model's (nothing measured it; scaling it alike made a mode the
  // measurements barely saw along x, its participation interpolated up from poses where it moves along x,
  // a spring of a few N/m across at the folded pose, and the cut's limit there zero).
  const PoseModes along = pose_modes(model, q, axis, count);
  const robot::PlanarChain chain = robot::at_pose(model, q);
  config::Config c = base;
  c.robot.locations = {{1, "TCP along the actuator", 1}, {2, "TCP across", 1}};
  c.robot.frfs.clear();
  const int across = 1 - axis;
  for (const auto& [name, response, excitation] :
       {std::tuple{"H11", 1, 1}, std::tuple{"H21", 2, 1}, std::tuple{"H22", 2, 2}}) {
    config::FrfConfig f;
    f.name = name;
    f.response_location = response, f.excitation_location = excitation;
    std::size_t along_index = 0;  // the mode's index in pose_modes' list (the modes that move the TCP along the axis)
    for (const robot::Mode& md : chain.modes(static_cast<std::size_t>(count))) {
      const double shapes = md.tcp_shape(response == 1 ? axis : across) * md.tcp_shape(excitation == 1 ? axis : across);
      const double w = kTwoPi * md.freq_hz;
      const bool moves_along = std::abs(md.tcp_shape(axis)) > 0.0 && w > 0.0;
      robot::ModeCorrection corr;  // the mapped mode that corrects this one, if any (scales 1: none)
      for (const robot::ModeCorrection& mc : along.corrections)
        if (moves_along && mc.model_index == static_cast<int>(along_index)) corr = mc;
      if (moves_along) ++along_index;
      if (!(std::abs(shapes) > 0.0) || !(w > 0.0)) continue;
      config::ModeConfig m;
      m.form = config::ModeForm::kStiffness;
      m.natural_freq_hz = md.freq_hz * corr.freq_scale;
      m.damping_ratio = robot::modal_damping_ratio(md) * corr.damping_scale;
      // Mass-normalised shapes at the mapped frequency: along the axis from the mapped stiffness along it,
      // across it the model's.
      const double w_mapped = kTwoPi * m.natural_freq_hz;
      const double phi_along = md.tcp_shape(axis),
                   k_along = moves_along ? w * w / (phi_along * phi_along) * corr.stiffness_scale : 0.0;
      const auto shape = [&](int location) {
        if (location == 2) return md.tcp_shape(across);
        return moves_along ? std::copysign(w_mapped / std::sqrt(k_along), phi_along) : phi_along;
      };
      m.stiffness_n_per_m = w_mapped * w_mapped / (shape(response) * shape(excitation));
      f.modes.push_back(m);
    }
    // The modes the map has from the measurements alone: measured along the axis only, so in H11 alone (their
    // shape across is unknown).
    if (response == 1 && excitation == 1)
      for (std::size_t i = 0; i < along.modes.size(); ++i)
        if (i < along.corrections.size() && along.corrections[i].measured_only()) f.modes.push_back(along.modes[i]);
    if (!f.modes.empty()) c.robot.frfs.push_back(f);
  }
  c.actuator.location = 1;
  c.sensor.location = 1;
  return c;
}

void with_region_compensator(config::Config& set, const config::RegionCompensatorConfig& c) {
  for (config::BlockConfig& b : set.controller.chain) {
    if (b.kind != config::BlockKind::kCompensator) continue;
    b.model = config::CompensatorModel::kRational;
    b.numerator = c.numerator;
    b.denominator = c.denominator;
    return;
  }
  throw config::ConfigError({config::Problem{
      set.source, {}, "controller.chain", "has no compensator block for a pose region's compensator to replace"}});
}

RegionSet design_region(const config::Config& cfg, const config::RobotModelConfig& model, std::size_t i) {
  const config::PoseScheduleConfig& s = *cfg.pose_schedule;
  const config::PoseRegionConfig& r = s.regions[i];
  RegionSet set;
  set.name = r.name;
  set.centre_deg = region_centre(r);
  const PoseModes centre = pose_modes(model, set.centre_deg, s.axis, s.modes);
  set.dominant_hz = centre.dominant_hz();
  set.gain_ns_per_m = r.gain_ns_per_m.value_or(cfg.controller.gain_ns_per_m);
  set.config = config_at_pose(cfg, centre);
  set.config.pose_schedule.reset();
  set.config.controller.match_freq_hz = r.match_freq_hz.value_or(set.dominant_hz);
  set.config.controller.gain_ns_per_m = set.gain_ns_per_m;
  if (r.compensator) with_region_compensator(set.config, *r.compensator);
  if (r.polarity) {
    set.polarity = *r.polarity;
  } else {
    const AnalysisResult a = analyse(LoopModel(set.config), set.gain_ns_per_m, cfg.controller.polarity);
    set.polarity = a.recommended_polarity;
  }
  set.config.controller.polarity = set.polarity;
  set.config.source = cfg.source + " [pose region " + r.name + "]";
  return set;
}

namespace {

// The set against the plant at every pose of the region's grid; throws at the first pose it fails.
void check_region(const config::Config& cfg, const config::RobotModelConfig& model, std::size_t i, RegionSet& set) {
  const config::PoseScheduleConfig& s = *cfg.pose_schedule;
  const double fraction = cfg.supervision.max_gain_fraction;
  set.k_max_ns_per_m = std::numeric_limits<double>::infinity();
  set.dominant_min_hz = std::numeric_limits<double>::infinity();
  set.dominant_max_hz = 0.0;
  BandWorst band;
  for (const auto& q : region_grid(s.regions[i], s.grid_points)) {
    const PoseModes pm = pose_modes(model, q, s.axis, s.modes);
    set.dominant_min_hz = std::min(set.dominant_min_hz, pm.dominant_hz());
    set.dominant_max_hz = std::max(set.dominant_max_hz, pm.dominant_hz());
    config::Config at = config_at_pose(set.config, pm);
    const LoopModel m(at);
    const double k_max = max_stable_gain(m, set.polarity).value_or(control::kMaxGainNsPerM);
    if (k_max < set.k_max_ns_per_m) set.k_max_ns_per_m = k_max, set.k_max_pose_deg = q;
    ++set.grid_poses;
    const std::string where = "region '" + set.name + "' at " + config::describe_pose(q) + " (dominant mode " +
                              fmt(pm.dominant_hz()) + " Hz; the set is matched at " + fmt(set.dominant_hz) +
                              " Hz, polarity " + std::to_string(set.polarity) + ")";
    if (!m.stable(set.gain_ns_per_m, set.polarity))
      throw region_error(cfg, i,
                         "has no stable set: " + where + " the loop is unstable at K = " + fmt(set.gain_ns_per_m) +
                             " N s/m (K_max there " + fmt(k_max) +
                             " N s/m): split the region or lower its gain_ns_per_m");
    if (set.gain_ns_per_m > fraction * k_max)
      throw region_error(cfg, i,
                         "has no set with margin: " + where + " K = " + fmt(set.gain_ns_per_m) +
                             " N s/m is above supervision.max_gain_fraction x K_max = " + fmt(fraction) + " x " +
                             fmt(k_max) + " N s/m: split the region or lower its gain_ns_per_m");
    if (band.add(mode_improvements(m, set.gain_ns_per_m, set.polarity), s.damping_band_min_hz, s.damping_band_max_hz))
      set.worst_mode_pose_deg = q;
  }
  set.worst_mode_improvement_pct = band.inside ? band.inside->improvement_pct : std::numeric_limits<double>::infinity();
  if (band.inside) set.worst_mode_hz = band.inside->freq_hz;
  if (band.outside) set.outside_band_pct = band.outside->improvement_pct, set.outside_band_hz = band.outside->freq_hz;
  set.improvement_centre_pct = driving_point_improvement_pct(LoopModel(set.config), set.gain_ns_per_m, set.polarity);
}

}  // namespace

PoseScheduleAnalysis analyse_pose_schedule(const config::Config& cfg) {
  PoseScheduleAnalysis out;
  if (!cfg.pose_schedule) return out;
  out.model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  for (std::size_t i = 0; i < cfg.pose_schedule->regions.size(); ++i) {
    RegionSet set = design_region(cfg, out.model, i);
    check_region(cfg, out.model, i, set);
    out.regions.push_back(std::move(set));
  }
  return out;
}

namespace {

// The set's driving-point improvement with these modes as its plant.
double improvement_with(const config::Config& set, const PoseModes& modes) {
  return driving_point_improvement_pct(LoopModel(config_at_pose(set, modes)), set.controller.gain_ns_per_m,
                                       set.controller.polarity);
}

}  // namespace

double predicted_improvement_pct(const config::Config& set, const config::RobotModelConfig& model,
                                 const config::PoseScheduleConfig& schedule, const std::vector<double>& q) {
  return improvement_with(set, pose_modes(model, q, schedule.axis, schedule.modes));
}

PredictedImprovement predicted_improvement(const config::Config& set, const config::RobotModelConfig& model,
                                           const config::PoseScheduleConfig& schedule, const std::vector<double>& q) {
  const PoseModes at = pose_modes(model, q, schedule.axis, schedule.modes);
  const auto improvement = [&](const PoseModes& pm) { return improvement_with(set, pm); };
  PredictedImprovement out;
  out.pct = improvement(at);
  if (at.corrections.size() != at.modes.size()) return out;
  double variance = 0.0;
  for (std::size_t i = 0; i < at.modes.size(); ++i)
    for (int quantity = 0; quantity < 3; ++quantity) {
      const robot::ModeCorrection& c = at.corrections[i];
      const config::ModeConfig& nominal = at.modes[i];
      const double sigma = quantity == 0 ? c.freq_sigma : quantity == 1 ? c.damping_sigma : c.stiffness_sigma;
      if (!(sigma > 0.0)) continue;
      double ends[2] = {0.0, 0.0};
      for (int side = 0; side < 2; ++side) {
        const double sign = side == 0 ? 1.0 : -1.0, scale = std::exp(sign * sigma);
        // The stiffness through its participation w^2 / k, whose sigma the map's is (relative to it): moved by
        // its sigma and kept above a thousandth of itself (a mode with next to no participation along the
        // axis, one a measurement did not see, moves by its absolute sigma, not by a factor).
        const double k =
            quantity != 2 ? nominal.stiffness_n_per_m : nominal.stiffness_n_per_m / std::max(1.0 + sign * sigma, 1e-3);
        PoseModes moved = at;
        moved.modes[i] = config::stiffness_mode(nominal.natural_freq_hz * (quantity == 0 ? scale : 1.0),
                                                nominal.damping_ratio * (quantity == 1 ? scale : 1.0), k);
        ends[side] = improvement(moved);
      }
      variance += 0.25 * (ends[0] - ends[1]) * (ends[0] - ends[1]);
    }
  out.sigma_pct = std::sqrt(variance);
  return out;
}

}  // namespace robodamp::analysis
