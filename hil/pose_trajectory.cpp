#include "hil/pose_trajectory.hpp"

#include <cmath>
#include <sstream>

#include <spdlog/spdlog.h>

#include "config/number_range.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::hil {

namespace {

config::ConfigError trajectory_error(const config::Config& cfg, const std::string& message) {
  return config::ConfigError({config::Problem{cfg.source, {}, "--pose-at", message}});
}

}  // namespace

PoseTrajectory::PoseTrajectory(const config::Config& cfg, std::vector<PoseWaypoint> points)
    : cfg_(cfg), points_(std::move(points)) {
  if (!cfg.pose_schedule)
    throw trajectory_error(cfg, "a pose trajectory needs the configuration's pose_schedule (the robot model)");
  if (points_.empty()) throw trajectory_error(cfg, "no waypoint");
  schedule_ = analysis::analyse_pose_schedule(cfg);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (auto p = config::pose_problem(schedule_.model, points_[i].joints_deg))
      throw trajectory_error(
          cfg, "waypoint " + std::to_string(i + 1) + " at " + config::format_number(points_[i].t_s) + " s: " + *p);
    if (i > 0 && points_[i].t_s < points_[i - 1].t_s)
      throw trajectory_error(cfg, "waypoint " + std::to_string(i + 1) + " at " + config::format_number(points_[i].t_s) +
                                      " s comes before the one before it: waypoints go in time order");
  }
}

std::vector<double> PoseTrajectory::at(double t) const {
  if (t <= points_.front().t_s) return points_.front().joints_deg;
  for (std::size_t i = 1; i < points_.size(); ++i) {
    const PoseWaypoint &a = points_[i - 1], &b = points_[i];
    if (t > b.t_s) continue;
    const double w = b.t_s > a.t_s ? (t - a.t_s) / (b.t_s - a.t_s) : 1.0;
    std::vector<double> q(a.joints_deg.size());
    for (std::size_t j = 0; j < q.size(); ++j) q[j] = a.joints_deg[j] + w * (b.joints_deg[j] - a.joints_deg[j]);
    return q;
  }
  return points_.back().joints_deg;
}

std::vector<PoseDwell> PoseTrajectory::dwells() const {
  std::vector<PoseDwell> out;
  for (std::size_t i = 1; i < points_.size(); ++i)
    if (points_[i].joints_deg == points_[i - 1].joints_deg && points_[i].t_s > points_[i - 1].t_s)
      out.push_back({points_[i - 1].t_s, points_[i].t_s, points_[i].joints_deg});
  return out;
}

std::vector<PoseDwell> PoseTrajectory::stops() const {
  std::vector<PoseDwell> out;
  for (const PoseDwell& d : dwells()) {
    if (!out.empty() && out.back().t1_s == d.t0_s && out.back().joints_deg == d.joints_deg)
      out.back().t1_s = d.t1_s;
    else
      out.push_back(d);
  }
  return out;
}

void check_measurement_stops(const PoseTrajectory& t, const analysis::CommissioningPlan& plan) {
  const std::vector<PoseDwell> stops = t.stops();
  if (stops.empty())
    throw trajectory_error(
        t.config(), "has no dwell (two waypoints at the same pose): --measure-out measures at the robot's stops");
  for (std::size_t k = 0; k < stops.size(); ++k)
    if (stops[k].t1_s - stops[k].t0_s < plan.duration_s)
      throw trajectory_error(t.config(),
                             "dwell " + std::to_string(k + 1) + " at " + config::describe_pose(stops[k].joints_deg) +
                                 " lasts " + config::format_number(stops[k].t1_s - stops[k].t0_s) +
                                 " s: the commissioning measurement at a stop needs " +
                                 config::format_number(plan.duration_s) +
                                 " s (commissioning: settle_s, the chirp, quiet_s, the impacts at every location)");
}

sim::PlantModel PoseTrajectory::plant_at(const std::vector<double>& q) const {
  const auto& s = *cfg_.pose_schedule;
  return sim::build_plant_model(
      analysis::config_at_pose(cfg_, analysis::pose_modes(schedule_.model, q, s.axis, s.modes)));
}

std::vector<std::pair<double, sim::PlantModel>> PoseTrajectory::retunes(double update_s) const {
  std::vector<std::pair<double, sim::PlantModel>> out;
  std::vector<double> last = at(0.0);
  for (long k = 1; static_cast<double>(k - 1) * update_s <= end_s(); ++k) {
    const double t = static_cast<double>(k) * update_s;
    if (std::vector<double> q = at(t); q != last) {
      out.emplace_back(t, plant_at(q));
      last = std::move(q);
    }
  }
  return out;
}

void PoseTrajectory::predict(PoseDwellReport& r) const {
  const auto& s = *cfg_.pose_schedule;
  r.dominant_hz = analysis::pose_modes(schedule_.model, r.joints_deg, s.axis, s.modes).dominant_hz();
  const auto region = config::region_of(s, r.joints_deg.data(), r.joints_deg.size());
  if (!region) return;
  const analysis::RegionSet& set = schedule_.regions[*region];
  r.region = set.name;
  r.predicted_pct = analysis::predicted_improvement_pct(set.config, schedule_.model, s, r.joints_deg);
}

DwellCampaigns::DwellCampaigns(const config::Config& cfg, sim::Plant& plant, const PoseTrajectory& trajectory,
                               const analysis::ImpactTest& test)
    : cfg_(cfg), trajectory_(trajectory), test_(test) {
  for (const PoseDwell& d : trajectory.dwells()) {
    const double start = d.t0_s + cfg.hil.settle_s;
    const int records = static_cast<int>(std::floor((d.t1_s - start) / cfg.bench.record_s));
    if (records < 1) {
      spdlog::warn(
          "robodamp plant: the dwell at {} from {:.1f} to {:.1f} s is too short for one {} s record after "
          "hil.settle_s = {} s: not measured",
          config::describe_pose(d.joints_deg), d.t0_s, d.t1_s, cfg.bench.record_s, cfg.hil.settle_s);
      continue;
    }
    config::Config& c = configs_.emplace_back(cfg);
    c.bench.averages = records;
    auto campaign = std::make_unique<analysis::ImpactCampaign>(c, plant, test);
    campaign->start(start);
    campaigns_.push_back(std::move(campaign));
    dwells_.push_back(d);
  }
}

void DwellCampaigns::before_step(std::size_t k) noexcept {
  for (auto& c : campaigns_) c->before_step(k);
}

void DwellCampaigns::after_step(std::size_t k) noexcept {
  for (auto& c : campaigns_) c->after_step(k);
}

std::vector<PoseDwellReport> DwellCampaigns::finish() const {
  std::vector<PoseDwellReport> out;
  const double lo = cfg_.analysis.band_min_hz, hi = cfg_.analysis.band_max_hz;
  for (std::size_t i = 0; i < campaigns_.size(); ++i) {
    PoseDwellReport r;
    r.joints_deg = dwells_[i].joints_deg;
    r.t0_s = dwells_[i].t0_s, r.t1_s = dwells_[i].t1_s;
    r.records = campaigns_[i]->records();
    trajectory_.predict(r);
    if (r.records > 0) {
      // The open-loop reference: the robot standing at the dwell's pose, the same hits, the amplifier off.
      sim::Plant open(trajectory_.plant_at(r.joints_deg), cfg_);
      if (cfg_.disturbances.drives_on) open.add_excitation(sim::make_drive_vibration(open.model(), cfg_));
      analysis::ImpactCampaign ref(configs_[i], open, test_);
      ref.start(campaigns_[i]->start_s());
      for (std::size_t k = 0; k < ref.end_tick(); ++k) {
        ref.before_step(k);
        (void)open.sense();
        open.step(0.0);
        ref.after_step(k);
      }
      const auto op = analysis::measured_peak(ref.receptance()[test_.excitation], lo, hi);
      const auto cl = analysis::measured_peak(campaigns_[i]->receptance()[test_.excitation], lo, hi);
      r.open_peak_m_per_n = op.magnitude_m_per_n;
      r.closed_peak_m_per_n = cl.magnitude_m_per_n, r.closed_peak_hz = cl.freq_hz;
      r.improvement_pct = (op.magnitude_m_per_n / cl.magnitude_m_per_n - 1.0) * 100.0;
      r.coherence_min = std::min(op.coherence_min, cl.coherence_min);
    }
    out.push_back(std::move(r));
  }
  return out;
}

bool parse_waypoint(const std::string& item, PoseWaypoint& out, std::string& error) {
  const auto colon = item.find(':');
  auto number = [&](const std::string& text, double& v) {
    std::size_t used = 0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      return false;
    }
    return used == text.size() && std::isfinite(v);
  };
  out = {};
  if (colon == std::string::npos || !number(item.substr(0, colon), out.t_s) || out.t_s < 0.0) {
    error = "'" + item + "' must be T:Q1,Q2,... with T >= 0 s the plant time and Q the joint angles in deg";
    return false;
  }
  std::stringstream ss(item.substr(colon + 1));
  std::string part;
  while (std::getline(ss, part, ',')) {
    double q = 0.0;
    if (!number(part, q) || std::abs(q) > 360.0) {
      error = "'" + item + "': joint angle '" + part + "' is not a number in -360..360 deg";
      return false;
    }
    out.joints_deg.push_back(q);
  }
  if (out.joints_deg.empty()) {
    error = "'" + item + "' has no joint angle";
    return false;
  }
  return true;
}

}  // namespace robodamp::hil
