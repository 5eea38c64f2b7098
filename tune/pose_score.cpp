#include "tune/pose_score.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <memory>

#include "analysis/loop_model.hpp"
#include "analysis/mode_improvement.hpp"
#include "analysis/pose_schedule.hpp"
#include "milling/structure.hpp"

namespace robodamp::tune {

namespace {

// The job with its structure replaced: the robot at the pose closed through the set at the TCP along the
// actuator's axis (the Evaluator's live loop), beside the structure's modal parts (a workpiece).
config::MillingConfig job_at_poses(const config::MillingConfig& job, const config::Config& cell) {
  config::MillingConfig out = job;
  const config::StructureConfig st = milling::robot_through_cell(job.selected_structure(), cell.actuator.location,
                                                                 cell.pose_schedule->axis, cell.source);
  out.structures = {st};
  out.structure = st.name;
  return out;
}

// The sets of one schedule, designed once.
std::vector<analysis::RegionSet> sets_of(const PoseTuneInput& in, const config::PoseScheduleConfig& schedule) {
  config::Config cfg = in.cell;
  cfg.pose_schedule = schedule;
  std::vector<analysis::RegionSet> out;
  for (std::size_t i = 0; i < schedule.regions.size(); ++i) out.push_back(analysis::design_region(cfg, in.model, i));
  return out;
}

void fold(ControllerScore& c, const PoseScore& p) {
  c.poses.push_back(p);
  if (p.regions.empty()) return;  // outside the workspace: no set runs there
  c.stable_everywhere = c.stable_everywhere && p.stable;
  c.worst_mode_improvement_pct = std::min(c.worst_mode_improvement_pct, p.worst_mode_improvement_pct);
  c.worst_improvement_pct = std::min(c.worst_improvement_pct, p.improvement_pct);
  if (p.outside_band_pct && (!c.outside_band_pct || *p.outside_band_pct < *c.outside_band_pct))
    c.outside_band_pct = p.outside_band_pct, c.outside_band_hz = p.outside_band_hz;
  if (p.damped_min_mm)
    c.damped_min_mm = std::min(c.damped_min_mm.value_or(std::numeric_limits<double>::infinity()), *p.damped_min_mm);
}

// One schedule at one pose: the worst over the sets that can run there.
PoseScore score_pose(const PoseTuneInput& in, const config::PoseScheduleConfig& schedule,
                     const std::vector<analysis::RegionSet>& sets, const MapPose& mp, const Evaluator* with_job) {
  const config::PoseScheduleConfig& s = *in.cell.pose_schedule;
  const analysis::PoseModes pm = analysis::pose_modes(in.model, mp.pose.joints_deg, s.axis, s.modes);
  PoseScore p;
  p.stable = true;
  p.worst_mode_improvement_pct = p.improvement_pct = std::numeric_limits<double>::infinity();
  analysis::BandWorst band;  // over the stable sets that can run here
  for (std::size_t i = 0; i < sets.size(); ++i) {
    if (!config::region_holds(schedule.regions[i], mp.pose.joints_deg.data(), mp.pose.joints_deg.size())) continue;
    p.regions.push_back(sets[i].name);
    const config::Config at = analysis::config_at_pose(sets[i].config, pm);
    const analysis::LoopModel m(at);
    const double k = sets[i].gain_ns_per_m;
    const int pol = sets[i].polarity;
    if (!m.stable(k, pol)) {
      p.region_improvement_pct.push_back(-std::numeric_limits<double>::infinity());
      p.stable = false;
      p.worst_mode_improvement_pct = p.improvement_pct = -std::numeric_limits<double>::infinity();
      if (with_job) p.damped_min_mm = 0.0;
      continue;
    }
    band.add(analysis::mode_improvements(m, k, pol), s.damping_band_min_hz, s.damping_band_max_hz);
    const double point = analysis::driving_point_improvement_pct(m, k, pol);
    p.region_improvement_pct.push_back(point);
    p.improvement_pct = std::min(p.improvement_pct, point);
    if (with_job) {
      const Evaluation e = with_job->assess(at);
      if (!p.damped_min_mm || e.accurate_min_mm < *p.damped_min_mm)
        p.damped_min_mm = e.accurate_min_mm, p.damped_min_rpm = e.accurate_min_rpm;
    }
  }
  if (band.inside && band.inside->improvement_pct < p.worst_mode_improvement_pct)
    p.worst_mode_improvement_pct = band.inside->improvement_pct, p.worst_mode_hz = band.inside->freq_hz;
  if (band.outside) p.outside_band_pct = band.outside->improvement_pct, p.outside_band_hz = band.outside->freq_hz;
  return p;
}

}  // namespace

std::vector<MapPose> workspace_map(const PoseTuneInput& in, int points, const std::vector<NamedPose>& held_out) {
  const config::PoseScheduleConfig& s = *in.cell.pose_schedule;
  config::PoseRegionConfig ws;
  ws.min_deg = s.workspace_min_deg, ws.max_deg = s.workspace_max_deg;
  std::vector<MapPose> out;
  for (NamedPose& q : mode_grid(in, ws, points)) out.push_back({std::move(q), "grid", 0.0, std::nullopt});
  for (const NamedPose& p : in.measured) out.push_back({p, "measured", 0.0, std::nullopt});
  for (const NamedPose& p : held_out) out.push_back({p, "held out", 0.0, std::nullopt});
  for (MapPose& m : out)
    m.dominant_hz = analysis::pose_modes(in.model, m.pose.joints_deg, s.axis, s.modes).dominant_hz();
  return out;
}

MapScores score_on_map(const PoseTuneInput& in, std::vector<MapPose> map,
                       const std::vector<std::pair<std::string, config::PoseScheduleConfig>>& schedules,
                       const std::optional<config::MillingConfig>& job, const PoseTuneProgress& progress) {
  MapScores out;
  std::vector<std::vector<analysis::RegionSet>> sets;
  for (const auto& [name, schedule] : schedules) {
    sets.push_back(sets_of(in, schedule));
    ControllerScore c;
    c.name = name;
    c.worst_mode_improvement_pct = c.worst_improvement_pct = std::numeric_limits<double>::infinity();
    out.controllers.push_back(c);
  }
  std::optional<config::MillingConfig> jp;
  if (job) jp = job_at_poses(*job, in.cell), out.method = "sampled-loop SDM";
  TuneSettings ts;
  ts.impact_peak_n = 0.0;  // the map scores depths and modes; the tune checked the actuator's limits
  const config::PoseScheduleConfig& s = *in.cell.pose_schedule;
  for (std::size_t k = 0; k < map.size(); ++k) {
    MapPose& mp = map[k];
    std::unique_ptr<Evaluator> ev;
    if (jp) {
      const analysis::PoseModes pm = analysis::pose_modes(in.model, mp.pose.joints_deg, s.axis, s.modes);
      ev = std::make_unique<Evaluator>(analysis::config_at_pose(sets.front().front().config, pm), jp, ts, mp.pose.name);
      mp.open_min_mm = ev->open_accurate_min_mm();
    }
    for (std::size_t c = 0; c < schedules.size(); ++c)
      fold(out.controllers[c], score_pose(in, schedules[c].second, sets[c], mp, ev.get()));
    if (progress)
      progress("map pose " + std::to_string(k + 1) + " of " + std::to_string(map.size()) + ": " + mp.pose.name);
  }
  out.map = std::move(map);
  return out;
}

std::size_t better_controller(const MapScores& s, double worse_mode_tolerance_pct) {
  const auto keeps = [&](const ControllerScore& c) {
    return c.worst_mode_improvement_pct >= -worse_mode_tolerance_pct;
  };
  std::size_t best = 0;
  for (std::size_t i = 1; i < s.controllers.size(); ++i) {
    const ControllerScore &a = s.controllers[best], &b = s.controllers[i];
    if (a.stable_everywhere != b.stable_everywhere) {
      if (b.stable_everywhere) best = i;
      continue;
    }
    if (keeps(a) != keeps(b)) {
      if (keeps(b)) best = i;
      continue;
    }
    if (a.damped_min_mm && b.damped_min_mm && std::abs(*b.damped_min_mm - *a.damped_min_mm) > 0.01 * *a.damped_min_mm) {
      if (*b.damped_min_mm > *a.damped_min_mm) best = i;
      continue;
    }
    if (b.worst_mode_improvement_pct > a.worst_mode_improvement_pct + 1.0) best = i;
  }
  return best;
}

}  // namespace robodamp::tune
