#include "runtime/machining_monitor.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <thread>

#include <spdlog/spdlog.h>

#include "analysis/pose_schedule.hpp"
#include "config/milling_config.hpp"
#include "rt/supervisor.hpp"
#include "rt/telemetry_frame.hpp"

namespace robodamp::runtime {

namespace {

constexpr int kLobeSpeeds = 80;                  // the live lobes' sweep: 81 speeds over the job's range
constexpr std::uint64_t kMaxHeldTicks = 100000;  // longer than the indicator's buffer (8 s at 5 kHz)
constexpr double kChatterLogPeriodS = 0.25;      // the indicator's verdict for the log, in loop time

// The job's spindle: without runout (time_domain.runout_um all zero) only the tooth harmonics are forced.
milling::ChatterIndicatorSettings indicator_settings(const config::Config& cfg) {
  milling::ChatterIndicatorSettings s;
  s.band_min_hz = cfg.analysis.band_min_hz;
  const config::MillingConfig job = config::load_milling_config(cfg.spindle.job_resolved);
  s.lines_per_revolution = milling::forced_lines_per_revolution(job);
  return s;
}

}  // namespace

MachiningMonitor::MachiningMonitor(const config::Config& cfg, std::vector<config::Config> sets, MachiningInputs in)
    : teeth_(cfg.spindle.teeth),
      active_set_(std::move(in.active_set)),
      handing_over_(std::move(in.handing_over)),
      robot_depth_mm_(std::move(in.robot_depth_mm)),
      pose_deg_(std::move(in.pose_deg)),
      path_ahead_deg_(std::move(in.path_ahead_deg)),
      pose_(in.pose),
      schedule_(std::move(in.schedule)),
      chatter_(cfg.loop.rate_hz, indicator_settings(cfg)) {
  set_configs_ = sets;
  config::MillingConfig job = config::load_milling_config(cfg.spindle.job_resolved);
  if (job.tool.teeth != cfg.spindle.teeth)
    throw config::ConfigError(
        {config::Problem{cfg.source,
                         {},
                         "spindle.teeth",
                         "= " + std::to_string(cfg.spindle.teeth) + " but the job " + cfg.spindle.job +
                             " cuts with tool.teeth = " + std::to_string(job.tool.teeth)}});
  unheard_modes_hz_ = milling::modes_above_band(job, cfg.spindle.structure, cfg.loop.rate_hz);
  if (const auto& u = unheard_modes_hz_; !u.empty())
    spdlog::warn(
        "machining: the live chatter indicator hears up to {:.0f} Hz (0.45 x the {:.0f} Hz loop rate); {} above "
        "it: a chatter there is not seen here (record the cut with a microphone or a fast accelerometer and run "
        "robodamp chatter)",
        milling::indicator_band_max_hz(cfg.loop.rate_hz), cfg.loop.rate_hz,
        u.size() == 1 ? fmt::format("the job's mode at {:.0f} Hz is", u[0])
                      : fmt::format("{} of the job's modes, {:.0f}-{:.0f} Hz, are", u.size(), u.front(), u.back()));
  const double rpm_min = job.lobes.rpm_min, rpm_max = std::min(job.lobes.rpm_max, cfg.spindle.rpm_max);
  for (int i = 0; i <= kLobeSpeeds; ++i) lobe_rpm_.push_back(rpm_min + (rpm_max - rpm_min) * i / kLobeSpeeds);
  milling::LiveStabilitySettings ls;
  ls.pose_step_deg = cfg.spindle.pose_step_deg;
  stability_ = std::make_unique<milling::LiveStability>(std::move(job), cfg.spindle.structure, std::move(sets), ls,
                                                        std::move(in.pose));
  milling::SpeedAdviceSettings as;
  as.grid_points = static_cast<std::size_t>(cfg.spindle.advice_grid_points);
  advisor_ = std::make_unique<SpeedAdvisor>(
      *stability_, [this] { return view(); }, rpm_min, rpm_max, std::move(in.on_advice), 0.2, as);
}

void MachiningMonitor::on_frame(const rt::TelemetryFrame& f) {
  std::lock_guard<std::mutex> lock(m_);
  if (const auto rpm = rt::spindle_rpm_set(f); rpm && f.command_value != rpm_) {
    rpm_ = *rpm;
    chatter_.reset();  // another speed: the window restarts
  }
  // Missed ticks keep their place in the indicator's time base (as gaps), bounded by its buffer.
  if (last_.tick > 0 && f.tick > last_.tick + 1)
    for (std::uint64_t k = std::min<std::uint64_t>(f.tick - last_.tick - 1, kMaxHeldTicks); k > 0; --k)
      chatter_.push(0.0, false);
  chatter_.push(f.accel_mps2, (f.flags & rt::kFlagFresh) != 0);
  last_ = f;
  // The log's verdicts every kChatterLogPeriodS of loop time, whoever else asks (the status thread, the
  // advisor on the wall clock): the same instants on any machine, in lockstep too.
  if (f.time_s >= next_chatter_log_s_) {
    next_chatter_log_s_ = f.time_s + kChatterLogPeriodS;
    if (rpm_ > 0.0) log_chatter(chatter_.evaluate(rpm_));
  }
}

Cutting cutting_state(double spindle_rpm, bool depth_measured, double depth_mm, const milling::ChatterIndicator& c) {
  if (!(spindle_rpm > 0.0)) return {dds::kNotCutting, "spindle stopped"};
  if (depth_measured)
    return depth_mm > 0.0 ? Cutting{dds::kCutting, "the robot's depth"}
                          : Cutting{dds::kNotCutting, "the robot's depth is 0"};
  if (!c.valid) return {dds::kCuttingUnknown, "the indicator's window is not full yet"};
  if (c.chatter) return {dds::kCutting, "chatter"};
  if (c.forced_lines) return {dds::kCutting, "tooth-passing lines in the vibration"};
  return {dds::kNotCutting, "no tooth-passing lines in the vibration"};
}

dds::MachiningSample MachiningMonitor::sample() { return view().sample; }

// Under m_, on the drain thread: the indicator's verdict changed (a valid verdict only: a restarting window
// says nothing), one line each way, with the loop time of the window's last sample.
void MachiningMonitor::log_chatter(const milling::ChatterIndicator& c) {
  if (!c.valid || c.chatter == chatter_logged_) return;
  chatter_logged_ = c.chatter;
  if (c.chatter)
    spdlog::warn(
        "machining: chatter at {:.2f} Hz at {:.3f} s, {:.0f} rpm (the live indicator over the last {:.1f} s: "
        "once-per-rev {:.2f}, non-harmonic share {:.2f}, {:.3f} m/s^2)",
        c.chatter_hz, last_.time_s, rpm_, chatter_.settings().window_s, c.once_per_rev_ratio, c.nonharmonic_share,
        c.nonharmonic_rms_mps2);
  else
    spdlog::info("machining: chatter ended at {:.3f} s, {:.0f} rpm (the live indicator)", last_.time_s, rpm_);
}

std::pair<std::size_t, double> MachiningMonitor::set_and_gain() {
  std::size_t set = active_set_ ? active_set_() : 0;
  if (set >= set_configs_.size()) set = 0;
  std::lock_guard<std::mutex> lock(m_);
  // The damper's limit for the chain that runs (during a hand-over the outgoing one, fading to K = 0 while the
  // incoming one warms up) at the gain it has (ramping included, 0 included: a speed schedule's open-loop band),
  // or, while it is off, at the set's gain at this speed (controller.speed_schedule).
  const bool active = static_cast<rt::State>(last_.state) == rt::State::kActive;
  return {set, active ? last_.gain_ns_per_m : config::scheduled_gain_ns_per_m(set_configs_[set], set, rpm_)};
}

std::vector<double> MachiningMonitor::pose_now() const {
  return pose_deg_ && stability_->pose_dependent() ? pose_deg_() : std::vector<double>{};
}

void MachiningMonitor::add_to_trail(double time_s, std::size_t set, double gain, const milling::LiveLimits& l) {
  std::lock_guard<std::mutex> lock(m_);
  const bool same = latest_ && latest_->set == set && latest_->gain_ns_per_m == gain && latest_->limits.rpm == l.rpm &&
                    latest_->limits.pose_deg == l.pose_deg;
  latest_ = milling::LiveLimitsRecord{time_s, set, gain, l};
  if (same || trail_.size() >= kTrailEntries) return;
  trail_.push_back(*latest_);
  spdlog::info(
      "machining: at pose {}, {:.0f} rpm, set {}, K {:.0f} N s/m: limit open {:.3f} mm ({}), damped {:.3f} mm ({}){}{}",
      l.pose_deg.empty() ? std::string("not known (the set's own plant)") : config::describe_pose(l.pose_deg), l.rpm,
      set, gain, l.open_mm, l.open_method, l.damped_mm, l.method.empty() ? "no damped FRF" : l.method,
      l.problem.empty() ? "" : ": ", l.problem);
}

void MachiningMonitor::await_limits(double time_s, double rpm, std::size_t set, double gain,
                                    const std::vector<double>& pose_deg) {
  milling::LiveStability::SweepPoint p{rpm, set, gain, stability_->grid_pose(pose_deg)};
  std::lock_guard<std::mutex> lock(m_);
  await_state(awaited_, kAwaited, time_s, std::move(p));
}

void MachiningMonitor::trail_awaited(const milling::LiveStability::SweepPoint& now) {
  std::vector<AwaitedState> waiting;
  {
    std::lock_guard<std::mutex> lock(m_);
    waiting = awaited_;
  }
  for (const auto& [t, last_s, p] : waiting) {
    if (same_state(p, now)) continue;  // still there: its limits join the trail as the view finds them
    const std::vector<milling::LiveLimits> got = stability_->known(std::vector{p});  // never waits
    if (got.empty()) continue;
    const milling::LiveLimits& l = got.front();
    std::lock_guard<std::mutex> lock(m_);
    std::erase_if(awaited_,
                  [&, t = t](const AwaitedState& a) { return a.met_s == t && a.point.pose_deg == p.pose_deg; });
    const bool met = std::any_of(trail_.begin(), trail_.end(), [&, &p = p](const milling::LiveLimitsRecord& r) {
      return r.set == p.set && r.gain_ns_per_m == p.gain_ns_per_m && r.limits.rpm == l.rpm &&
             r.limits.pose_deg == l.pose_deg;
    });
    if (met || trail_.size() >= kTrailEntries) continue;
    const auto at = std::upper_bound(trail_.begin(), trail_.end(), t,
                                     [](double time, const milling::LiveLimitsRecord& r) { return time < r.time_s; });
    trail_.insert(at, milling::LiveLimitsRecord{t, p.set, p.gain_ns_per_m, l});
    spdlog::info(
        "machining: at pose {} (left before its limits were ready), {:.0f} rpm, set {}: limit open {:.3f} mm, "
        "damped {:.3f} mm",
        config::describe_pose(l.pose_deg), l.rpm, p.set, l.open_mm, l.damped_mm);
  }
}

void MachiningMonitor::complete_trail(double timeout_s) {
  if (!stability_->pose_dependent()) return;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::vector<AwaitedState> waiting;
  {
    std::lock_guard<std::mutex> lock(m_);
    waiting = awaited_;
  }
  for (const auto& [met_s, last_s, p] : waiting) {
    if (std::chrono::steady_clock::now() >= end) break;
    try {
      (void)stability_->compute(p.rpm, p.set, p.gain_ns_per_m, p.pose_deg);  // cached: trail_awaited finds it
    } catch (const std::exception& e) {  // a model that cannot be built there: the state stays out of the trail
      spdlog::warn("machining: the limits at pose {} for the run's summary: {}", config::describe_pose(p.pose_deg),
                   e.what());
    }
  }
  trail_awaited({});  // the run is over: no state is the robot's now
}

std::optional<milling::LiveLimits> MachiningMonitor::moved_from(double rpm, std::size_t set, double gain) const {
  std::lock_guard<std::mutex> lock(m_);
  if (!latest_) return std::nullopt;
  const milling::LiveLimitsRecord& last = *latest_;
  if (last.set != set || std::abs(last.gain_ns_per_m - gain) > 5.0 || std::abs(last.limits.rpm - rpm) > 0.5)
    return std::nullopt;
  return last.limits;
}

std::vector<milling::LiveLimitsRecord> MachiningMonitor::trail() const {
  std::lock_guard<std::mutex> lock(m_);
  return trail_;
}

void MachiningMonitor::mode_spread(dds::MachiningSample& s) {
  if (!pose_ || !pose_->model.measured_modes || s.limits_pose_deg.empty()) return;
  std::lock_guard<std::mutex> lock(m_);
  if (s.limits_pose_deg != spread_pose_) {
    spread_pose_ = s.limits_pose_deg;
    spread_pct_ = spread_nearest_deg_ = -1.0;
    try {
      const analysis::PoseModes pm = analysis::pose_modes(pose_->model, spread_pose_, pose_->axis, pose_->modes);
      if (!pm.corrections.empty()) {
        spread_pct_ = 0.0;
        for (const auto& c : pm.corrections) spread_pct_ = std::max(spread_pct_, 100.0 * c.freq_sigma);
        spread_nearest_deg_ = pm.nearest_measured_deg;
      }
    } catch (const std::exception&) {  // a pose outside the model's travel: no spread to say
    }
  }
  s.mode_spread_pct = spread_pct_, s.nearest_measured_deg = spread_nearest_deg_;
}

AdviceView MachiningMonitor::view() {
  AdviceView v;
  dds::MachiningSample& s = v.sample;
  v.handing_over = handing_over_ && handing_over_();
  const auto [set, gain] = set_and_gain();
  milling::ChatterIndicator c;
  {
    std::lock_guard<std::mutex> lock(m_);
    s.tick = last_.tick;
    s.time_s = last_.time_s;
    s.spindle_rpm = rpm_;
    s.loop_active = static_cast<rt::State>(last_.state) == rt::State::kActive;
    c = chatter_.evaluate(rpm_);
    s.indicator_valid = c.valid;
    s.once_per_rev_ratio = c.once_per_rev_ratio;
    s.nonharmonic_share = c.nonharmonic_share;
    s.chatter_hz = c.chatter_hz;
    s.chatter = c.chatter;
  }
  s.tooth_passing_hz = s.spindle_rpm * teeth_ / 60.0;
  const double robot_depth = robot_depth_mm_ ? robot_depth_mm_() : std::nan("");
  s.depth_measured = std::isfinite(robot_depth);
  s.depth_mm = s.depth_measured ? robot_depth : stability_->depth_mm();  // the robot's 0: the tool is out of the cut
  const Cutting cutting = cutting_state(s.spindle_rpm, s.depth_measured, s.depth_mm, c);
  s.cutting = cutting.state, s.cutting_reason = cutting.reason;
  s.pose_deg = pose_now();
  s.limits_pose_deg = stability_->grid_pose(s.pose_deg);
  if (s.spindle_rpm > 0.0) {
    auto l = stability_->lookup(s.spindle_rpm, set, gain, s.pose_deg);
    s.limits_ready = l.has_value();
    if (stability_->pose_dependent()) {
      if (l)
        add_to_trail(s.time_s, set, gain, *l);
      else
        await_limits(s.time_s, s.spindle_rpm, set, gain, s.pose_deg);
      trail_awaited({s.spindle_rpm, set, gain, stability_->grid_pose(s.pose_deg)});
    }
    // The robot moved on to a grid point not computed yet: the limits at the last pose, for the same speed,
    // set and K, with that pose (limits_ready false says they are being recomputed).
    if (!l) l = moved_from(s.spindle_rpm, set, gain);
    if (l) {
      s.limits_pose_deg = l->pose_deg;
      s.open_limit_mm = l->open_mm;
      s.damped_limit_mm = l->damped_mm;
      s.limit_method = l->method;
      s.limit_mm = s.loop_active ? l->damped_mm : l->open_mm;
      s.depth_warning = s.depth_mm > s.limit_mm;
    }
  }
  mode_spread(s);
  v.parameter_set = set;
  v.gain_ns_per_m = gain;
  if (set_configs_[set].controller.speed_schedule)  // the set and K the schedule runs at each candidate speed
    v.controller_at = [sets = &set_configs_, set = set](double rpm) {
      std::size_t at = config::scheduled_set((*sets)[set], set, rpm);
      if (at >= sets->size()) at = 0;
      return std::pair{at, config::scheduled_gain_ns_per_m((*sets)[at], at, rpm)};
    };
  if (path_ahead_deg_ && !s.limits_pose_deg.empty()) {
    v.path_ahead_deg = path_ahead_deg_();
    // A pose ahead: the region that holds it (the current one while it does: the hand-over's hysteresis), its
    // set and K; outside every region, region 0's, as the schedule runs there.
    if (schedule_)
      v.controller_at_pose = [sets = &set_configs_, schedule = &*schedule_, set = set](const std::vector<double>& pose,
                                                                                       double) {
        std::size_t at = config::region_of(*schedule, pose.data(), pose.size(), set).value_or(0);
        if (at >= sets->size()) at = 0;
        return std::pair{at, (*sets)[at].controller.gain_ns_per_m};
      };
  }
  return v;
}

// A speed schedule's envelope: each lobe speed with the set and K the schedule runs there (independent of what
// runs now, so swept once).
std::optional<dds::LobesSample> MachiningMonitor::scheduled_lobes(std::size_t active) {
  std::vector<milling::LiveStability::SweepPoint> points;
  for (const double rpm : lobe_rpm_) {
    std::size_t at = config::scheduled_set(set_configs_[active], active, rpm);
    if (at >= set_configs_.size()) at = 0;
    points.push_back({rpm, at, config::scheduled_gain_ns_per_m(set_configs_[at], at, rpm), lobes_pose_});
  }
  if (!lobes_swept_) stability_->sweep(points), lobes_swept_ = true;
  const std::vector<milling::LiveLimits> known = stability_->known(points);
  if (known.size() == lobes_published_) return std::nullopt;
  lobes_published_ = known.size();
  dds::LobesSample out;
  {
    std::lock_guard<std::mutex> lock(m_);
    out.time_s = last_.time_s;
  }
  out.speed_scheduled = true;
  out.pose_deg = lobes_pose_;
  out.depth_mm = stability_->depth_mm();
  for (const auto& l : known) {
    out.rpm.push_back(l.rpm);
    out.open_limit_mm.push_back(l.open_mm);
    out.damped_limit_mm.push_back(l.damped_mm);
  }
  out.method = "sampled-loop SDM, speed schedule";
  return out;
}

std::optional<dds::LobesSample> MachiningMonitor::lobes() {
  const auto [set, gain] = set_and_gain();
  const std::vector<double> pose = stability_->grid_pose(pose_now());
  if (set_configs_[set].controller.speed_schedule) {
    // The envelope depends on the schedule, not on the K passing now (a schedule of K alone: on the set).
    const bool chooses = !set_configs_[set].controller.speed_schedule->controllers.empty();
    const std::size_t owner = chooses ? 0 : set;
    if (!lobes_scheduled_ || owner != lobes_set_ || pose != lobes_pose_)
      lobes_scheduled_ = true, lobes_set_ = owner, lobes_pose_ = pose, lobes_swept_ = false, lobes_published_ = 0;
    return scheduled_lobes(owner);
  }
  lobes_scheduled_ = false;
  if (set != lobes_set_ || gain != lobes_gain_ ||
      pose != lobes_pose_) {  // a new state, a ramp, a move: wait for it to hold
    lobes_set_ = set, lobes_gain_ = gain, lobes_pose_ = pose;
    lobes_swept_ = false, lobes_published_ = 0;
    return std::nullopt;
  }
  if (!lobes_swept_) stability_->sweep(set, gain, lobe_rpm_, pose), lobes_swept_ = true;
  const std::vector<milling::LiveLimits> known = stability_->known(set, gain, pose);
  if (known.size() == lobes_published_) return std::nullopt;
  lobes_published_ = known.size();
  dds::LobesSample out;
  {
    std::lock_guard<std::mutex> lock(m_);
    out.time_s = last_.time_s;
  }
  out.parameter_set = set;
  out.gain_ns_per_m = gain;
  out.pose_deg = pose;
  out.depth_mm = stability_->depth_mm();
  for (const auto& l : known) {
    out.rpm.push_back(l.rpm);
    out.open_limit_mm.push_back(l.open_mm);
    out.damped_limit_mm.push_back(l.damped_mm);
    if (!l.method.empty() && out.method.find(l.method) == std::string::npos)
      out.method += (out.method.empty() ? "" : " + ") + l.method;  // e.g. "sampled-loop SDM + zero-order preview"
  }
  return out;
}

dds::MachiningSample MachiningMonitor::settled_sample(double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  dds::MachiningSample s = sample();
  while (s.spindle_rpm > 0.0 && !s.limits_ready && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    s = sample();
  }
  return s;
}

}  // namespace robodamp::runtime
