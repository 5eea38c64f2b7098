#include "milling/live_stability.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "analysis/loop_model.hpp"
#include "analysis/pose_schedule.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

namespace {

// The job's structure, or with PoseDynamics the robot through the cell's loop beside its modal parts.
config::StructureConfig pick_structure(const config::MillingConfig& job, const std::string& name,
                                       const config::Config& cell, const std::optional<PoseDynamics>& pose,
                                       bool needs_controller = true) {
  const std::string wanted = name.empty() ? job.structure : name;
  const config::StructureConfig* s = job.find_structure(wanted);
  if (s == nullptr && name.empty() && !job.structures.empty()) s = &job.structures.front();
  if (s == nullptr)
    throw config::ConfigError(
        {config::Problem{job.source, {}, "structure", "the job has no structure named '" + wanted + "'"}});
  if (pose) return robot_through_cell(*s, cell.actuator.location, pose->axis, cell.source);
  if (!needs_controller) return *s;
  bool has_controller = false;
  for (const auto& p : s->parts) has_controller = has_controller || p.controller.has_value();
  if (!has_controller)
    throw config::ConfigError(
        {config::Problem{job.source,
                         {},
                         "structures." + s->name,
                         "live stability needs a part with a controller (the damper's location and direction)"}});
  return *s;
}

}  // namespace

LiveStability::LiveStability(config::MillingConfig job, const std::string& structure, std::vector<config::Config> sets,
                             LiveStabilitySettings s, std::optional<PoseDynamics> pose)
    : job_(std::move(job)), sets_(std::move(sets)), s_(s), pose_(std::move(pose)) {
  if (sets_.empty())
    throw config::ConfigError({config::Problem{job_.source, {}, "", "live stability needs a loop configuration"}});
  structure_ = pick_structure(job_, structure, sets_.front(), pose_);
  if (pose_) {
    job_structure_ = pick_structure(job_, structure, sets_.front(), std::nullopt, false);
    // At a pose the loop's plant is the model's in its plane (config_in_plane_at_pose: location 1 the TCP along
    // the actuator, 2 across): the robot through the loop in both directions.
    plane_structure_ = robot_through_cell(job_structure_, 1, pose_->axis, sets_.front().source, 2);
  }
  worker_.start("rd-live-limits", [this](std::stop_token stop) { worker(stop); });
  sweeper_.start("rd-live-sweep", [this](std::stop_token stop) { sweeper(stop); });
}

LiveStability::~LiveStability() {
  sweeper_.request_stop();  // both asked first: neither starts another limit while the other is joined
  worker_.request_stop();
  sweeper_.stop();
  worker_.stop();
}

LiveStability::Key LiveStability::key(double rpm, std::size_t set, double gain,
                                      const std::vector<double>& pose_deg) const {
  Key k{std::lround(rpm / s_.rpm_step), set < sets_.size() ? set : 0, std::lround(gain / s_.gain_step_ns_per_m), {}};
  if (!pose_) return k;
  for (const double q : pose_deg) {
    if (!std::isfinite(q)) return {k.rpm, k.set, k.gain, {}};  // a joint not known: the pose is not known
    k.pose.push_back(std::lround(q / s_.pose_step_deg));
  }
  return k;
}

std::vector<double> LiveStability::pose_of(const Key& k) const {
  std::vector<double> out;
  for (const long q : k.pose) out.push_back(static_cast<double>(q) * s_.pose_step_deg);
  return out;
}

std::vector<double> LiveStability::grid_pose(const std::vector<double>& pose_deg) const {
  return pose_of(key(0.0, 0, 0.0, pose_deg));
}

config::Config LiveStability::loop_config(std::size_t set, const std::vector<double>& pose_deg) const {
  const config::Config& base = sets_[set < sets_.size() ? set : 0];
  if (!pose_ || pose_deg.empty()) return base;
  return analysis::config_in_plane_at_pose(base, pose_->model, pose_deg, pose_->axis, pose_->modes);
}

std::optional<LiveLimits> LiveStability::lookup(double rpm, std::size_t set, double gain_ns_per_m,
                                                const std::vector<double>& pose_deg) {
  const Key k = key(rpm, set, gain_ns_per_m, pose_deg);
  std::lock_guard<std::mutex> lock(m_);
  if (const auto it = cache_.find(k); it != cache_.end()) return it->second;
  wanted_ = k;
  worker_.notify();
  return std::nullopt;
}

LiveLimits LiveStability::compute(double rpm, std::size_t set, double gain_ns_per_m,
                                  const std::vector<double>& pose_deg) {
  const Key k = key(rpm, set, gain_ns_per_m, pose_deg);
  {
    std::lock_guard<std::mutex> lock(m_);
    if (const auto it = cache_.find(k); it != cache_.end()) return it->second;
  }
  LiveLimits l = evaluate(k);
  std::lock_guard<std::mutex> lock(m_);
  ++computations_;
  if (cache_.size() < s_.cache_entries) cache_.emplace(k, l);
  return l;
}

void LiveStability::sweep(std::size_t set, double gain_ns_per_m, const std::vector<double>& rpm,
                          const std::vector<double>& pose_deg) {
  std::lock_guard<std::mutex> lock(m_);
  sweep_.clear();
  for (const double r : rpm)
    if (r > 0.0) sweep_.push_back(key(r, set, gain_ns_per_m, pose_deg));
  sweeper_.notify();
}

std::vector<LiveLimits> LiveStability::known(std::size_t set, double gain_ns_per_m,
                                             const std::vector<double>& pose_deg) const {
  const Key k = key(0.0, set, gain_ns_per_m, pose_deg);
  std::vector<LiveLimits> out;
  std::lock_guard<std::mutex> lock(m_);
  for (const auto& [key, l] : cache_)  // the key orders by speed first
    if (key.set == k.set && key.gain == k.gain && key.pose == k.pose && key.rpm > 0) out.push_back(l);
  return out;
}

void LiveStability::sweep(const std::vector<SweepPoint>& points) {
  std::lock_guard<std::mutex> lock(m_);
  sweep_.clear();
  for (const SweepPoint& p : points)
    if (p.rpm > 0.0) sweep_.push_back(key(p.rpm, p.set, p.gain_ns_per_m, p.pose_deg));
  sweeper_.notify();
}

std::vector<LiveLimits> LiveStability::known(const std::vector<SweepPoint>& points) const {
  std::vector<LiveLimits> out;
  std::lock_guard<std::mutex> lock(m_);
  for (const SweepPoint& p : points)
    if (const auto it = cache_.find(key(p.rpm, p.set, p.gain_ns_per_m, p.pose_deg)); p.rpm > 0.0 && it != cache_.end())
      out.push_back(it->second);
  return out;
}

std::uint64_t LiveStability::computations() const {
  std::lock_guard<std::mutex> lock(m_);
  return computations_;
}

void LiveStability::worker(std::stop_token stop) {
  std::unique_lock<std::mutex> lock(m_);
  while (worker_.wait(lock, stop, [this] { return wanted_.has_value(); })) {
    const Key k = *wanted_;
    wanted_.reset();
    if (cache_.count(k) != 0) continue;
    lock.unlock();
    LiveLimits l = evaluate_reported(k);
    lock.lock();
    store(k, std::move(l));
  }
}

LiveLimits LiveStability::evaluate_reported(const Key& k) const {
  try {
    return evaluate(k);
  } catch (const std::exception& e) {  // a model that cannot be built: reported, never thrown at the cell
    LiveLimits l;
    l.rpm = static_cast<double>(k.rpm) * s_.rpm_step;
    l.pose_deg = pose_of(k);
    l.open_mm = l.damped_mm = 0.0;
    l.damped_valid = false;
    l.problem = e.what();
    return l;
  }
}

void LiveStability::store(const Key& k, LiveLimits l) {
  ++computations_;
  if (cache_.size() >= s_.cache_entries) cache_.clear();  // bounded; a run visits few states
  cache_.emplace(k, std::move(l));
}

void LiveStability::sweeper(std::stop_token stop) {
  // Below every other thread of the cell (nice 10: about 10 % of a core against a busy nice-0 thread), so the
  // sweep yields to the cell's drivers, its telemetry and the advice (the loop itself is real time) but still
  // moves on a loaded machine. At nice 19 (1.5 %) the browser test's cell drew fewer than 20 speeds in 240 s
  // under a CPU hog on both cores.
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  std::unique_lock<std::mutex> lock(m_);
  while (sweeper_.wait(lock, stop, [this] { return !sweep_.empty(); })) {
    const Key k = sweep_.front();
    sweep_.pop_front();
    if (cache_.count(k) != 0) continue;
    lock.unlock();
    LiveLimits l = evaluate_reported(k);
    lock.lock();
    store(k, std::move(l));
  }
}

LiveLimits LiveStability::evaluate(const Key& k) const {
  LiveLimits out = evaluate_loop(k);
  if (pose_ && !out.pose_deg.empty() && out.rpm > 0.0) check_loop_model(out, k.gain > 0);
  return out;
}

void LiveStability::check_loop_model(LiveLimits& l, bool damping) const {
  config::StructureConfig whole;  // the job's modal parts and the robot model at the pose
  whole.name = "robot_model_at_pose";
  for (const auto& part : job_structure_.parts)
    if (!part.pose && !part.controller) whole.parts.push_back(part);
  config::StructurePartConfig robot;
  robot.name = "robot";
  robot.pose = config::PosePartConfig{pose_->model_path, l.pose_deg};
  whole.parts.push_back(robot);
  const SdmPoint o =
      AccurateStability(Structure(whole, false), job_).critical(l.rpm, std::isfinite(l.open_mm) ? l.open_mm : 1.0);
  l.loop_open_mm = l.open_mm;
  l.open_mm = o.critical_depth_mm;
  l.open_chatter_hz = o.chatter_hz;
  l.open_method = "SDM, the robot model at the pose";
  l.loop_model_verified = std::abs(l.loop_open_mm / l.open_mm - 1.0) <= s_.loop_model_tolerance;
  if (!damping) l.damped_mm = l.open_mm, l.damped_chatter_hz = l.open_chatter_hz;  // K = 0: the open loop
  if (l.loop_model_verified || !l.damped_valid || !damping) return;
  char b[400];
  std::snprintf(
      b, sizeof b,
      "at this pose the robot's modes above the loop's %d set the limit: open %.3f mm by the robot model, %.3f mm by "
      "the loop's model, more than %.0f %% apart (pose_schedule.modes); the damper's effect is not claimed",
      pose_->modes, l.open_mm, l.loop_open_mm, 100.0 * s_.loop_model_tolerance);
  l.problem = b;
  l.damped_mm = l.open_mm;
  l.damped_chatter_hz = l.open_chatter_hz;
  l.analysed_rpm = l.rpm;
  l.method = "open loop (the damped model is not verified at this pose)";
}

LiveLimits LiveStability::evaluate_loop(const Key& k) const {
  LiveLimits out;
  out.rpm = static_cast<double>(k.rpm) * s_.rpm_step;
  out.pose_deg = pose_of(k);
  const config::Config cfg = loop_config(k.set, out.pose_deg);
  const double gain = static_cast<double>(k.gain) * s_.gain_step_ns_per_m;
  const double inf = std::numeric_limits<double>::infinity();
  out.open_mm = out.damped_mm = inf;
  if (out.rpm <= 0.0) return out;

  config::LobesConfig lobes = job_.lobes;
  lobes.rpm_min = std::min(lobes.rpm_min, out.rpm);
  lobes.rpm_max = std::max(lobes.rpm_max, out.rpm);
  const ChatterProcess process = chatter_process(job_.tool, job_.material, job_.cut);
  const int polarity = cfg.controller.polarity;

  // The zero-order limits are the accurate method's first guesses (and, labelled, the answer where the
  // sampled loop cannot step the speed).
  const config::StructureConfig& st = out.pose_deg.empty() ? structure_ : plane_structure_;
  const auto plain = std::make_shared<const analysis::LoopModel>(cfg);
  const Structure open(st, false, {plain, gain, polarity});
  const auto open_zoa = LobeModel(open, process, lobes).limit_at(out.rpm);
  const SdmPoint o = AccurateStability(open, job_).critical(out.rpm, open_zoa ? open_zoa->b_lim_mm : 1.0);
  out.open_mm = o.critical_depth_mm;
  out.open_chatter_hz = o.chatter_hz;
  out.open_method = "SDM";
  out.analysed_rpm = out.rpm;
  if (gain <=
      0.0) {  // K 0 (a speed schedule's open-loop band): the damper commands nothing, the cut sees the open loop
    out.damped_mm = out.open_mm;
    out.damped_chatter_hz = out.open_chatter_hz;
    out.method = "SDM (K = 0: the open loop)";
    return out;
  }
  try {
    const Structure damped(st, true,
                           {std::make_shared<const analysis::LoopModel>(plain->at_speed(out.rpm)), gain, polarity});
    const auto zoa = LobeModel(damped, process, lobes).limit_at(out.rpm);
    const AccurateStability truth(damped, job_);
    if (out.rpm <= truth.max_rpm()) {
      const SdmPoint d = truth.critical(out.rpm, zoa ? zoa->b_lim_mm : 1.0);
      out.damped_mm = d.critical_depth_mm;
      out.damped_chatter_hz = d.chatter_hz;
      out.analysed_rpm = d.rpm;
      out.method = truth.method();
      // A speed schedule's band that vouches for less than the accurate method (its limit chattered in time).
      const std::size_t set = k.set;
      if (const auto cap = config::scheduled_depth_limit_mm(cfg, set, out.rpm);
          cap && *cap < out.damped_mm &&
          std::abs(config::scheduled_gain_ns_per_m(cfg, set, out.rpm) - gain) <= 0.5 * s_.gain_step_ns_per_m) {
        out.damped_mm = *cap;
        out.method += ", capped at the band's depth_limit_mm (the cut in time)";
      }
    } else {
      out.method = "zero-order preview";
      if (zoa) out.damped_mm = zoa->b_lim_mm, out.damped_chatter_hz = zoa->chatter_hz;
    }
  } catch (const config::ConfigError& e) {
    out.damped_valid = false;
    out.damped_mm = 0.0;
    out.problem = e.what();
  }
  return out;
}

}  // namespace robodamp::milling
