#include "runtime/cell.hpp"

#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "analysis/notch_speed_map.hpp"

#include "runtime/parameter_requests.hpp"
#include "runtime/speed_sets.hpp"
#include "sim_plant/excitation.hpp"

namespace robodamp::runtime {

Cell::Cell(const config::Config& cfg, CellOptions o) : cfg_(cfg), o_(std::move(o)) {
  if (o_.clock) cfg_.loop.clock = *o_.clock;
}

Cell::~Cell() {
  if (state_ == LifecycleState::kActive) (void)deactivate();
  if (state_ == LifecycleState::kInactive) (void)cleanup();
}

namespace {

// The extra delay the loop at its configured gain tolerates for good (s; 0 when none is known): how long a
// run of overruns may last before it trips (supervision.overrun_delay_margin_share).
double delay_margin_s(const analysis::LoopModel& m, const config::Config& c, std::optional<double> k_max) {
  const analysis::Margins mg = analysis::margins(m, c.controller.gain_ns_per_m, c.controller.polarity, k_max);
  return mg.delay_margin_ms ? *mg.delay_margin_ms * 1e-3 : 0.0;
}

// The harmonic notches' speed map (analysis/notch_speed_map.hpp): the speeds refused go into the
// controller's parameters, and each refused interval is reported once here. From the set's own model: every
// speed's loop shares its sampled plant.
control::ControllerParams with_notch_speed_map(const analysis::LoopModel& m) {
  const config::Config& cfg = m.config();
  control::ControllerParams p = m.chain().params;
  const analysis::NotchSpeedMap map = analysis::notch_speed_map(m);
  for (const auto& [lo, hi] : map.refused_rpm) {
    std::string why;
    for (const auto& pt : map.points)
      if (pt.refused && pt.rpm >= lo && pt.rpm <= hi) {
        why = pt.reason;
        break;
      }
    spdlog::warn("{}: the harmonic notches are refused at {:.0f}-{:.0f} rpm ({}); they park there", cfg.source, lo, hi,
                 why);
  }
  analysis::apply_refused_speeds(map, p);
  return p;
}

}  // namespace

std::vector<Component*> Cell::components() {
  std::vector<Component*> v;
  for (Component* c : std::initializer_list<Component*>{sim_.get(), can_.get(), modbus_.get(), dds_.get()})
    if (c != nullptr) v.push_back(c);
  return v;
}

Status Cell::configure() {
  if (state_ != LifecycleState::kUnconfigured)
    return {StatusKind::kWrongState, std::string("cell: cannot configure while ") + to_string(state_)};
  if (cfg_.can.has_value() != cfg_.modbus.has_value())
    return {StatusKind::kConfigError,
            config::ConfigError({{cfg_.source,
                                  {},
                                  cfg_.can ? "modbus" : "can",
                                  "missing: a hardware cell needs both the can section (sensor and command frames) and "
                                  "the modbus section (the amplifier's enable and status)"}})
                .what()};
  Status s = plan_analysis();
  if (s.ok()) s = compose_devices();
  if (!s.ok()) {
    release();  // the one rollback path: whatever the failed step had built
    return s;
  }
  state_ = LifecycleState::kInactive;
  return {};
}

// The analysis the cell runs on: the pose schedule's sets, the loop model, its stability and K_max, and
// the supervisor built on that verdict.
Status Cell::plan_analysis() {
  if (Status s = configure_pose_schedule(); !s.ok()) return s;
  const config::Config& set0 = pose_schedule_.regions.empty() ? cfg_ : pose_schedule_.regions.front().config;
  try {
    model_ = std::make_unique<analysis::LoopModel>(set0);
  } catch (const config::ConfigError& e) {
    return {StatusKind::kConfigError, e.what()};
  }
  const int polarity = set0.controller.polarity;
  stable_ = model_->stable(set0.controller.gain_ns_per_m, polarity);
  max_stable_gain_ = analysis::max_stable_gain(*model_, polarity);
  double k_max = max_stable_gain_.value_or(control::kMaxGainNsPerM);
  if (!pose_schedule_.regions.empty()) {
    k_max = std::min(k_max, pose_schedule_.regions.front().k_max_ns_per_m);
    max_stable_gain_ = k_max;
  }
  rt::SupervisorSettings settings =
      config::supervisor_settings(cfg_, stable_, k_max, delay_margin_s(*model_, set0, max_stable_gain_));
  settings.pose_scheduled = !pose_schedule_.regions.empty() && !o_.pose_schedule_off;
  supervisor_ = std::make_unique<rt::Supervisor>(settings, with_notch_speed_map(*model_));
  if (settings.pose_scheduled) configure_pose_sets();
  return {};
}

// The devices and the loop around the supervisor: the telemetry ring, the backend's components, the loop
// and its arming, the parameter sets and, with spindle.job, the machining monitor.
Status Cell::compose_devices() {
  ring_ = std::make_unique<rt::SpscRing<rt::TelemetryFrame>>(static_cast<std::size_t>(cfg_.telemetry.ring_frames));
  if (Status s = configure_devices(); !s.ok()) return s;
  rt::SensorSource* sensor = can_ ? static_cast<rt::SensorSource*>(&can_->driver()) : &sim_->backend();
  rt::ActuatorSink* actuator = can_ ? static_cast<rt::ActuatorSink*>(&can_->driver()) : &sim_->backend();
  rt::AmplifierIo* io = modbus_ ? static_cast<rt::AmplifierIo*>(&modbus_->client()) : &sim_->backend();
  loop_ = std::make_unique<rt::Loop>(cfg_.loop.rate_hz, cfg_.loop.clock, *supervisor_, *sensor, *actuator, *io,
                                     ring_.get());
  if (o_.chirp.enabled) loop_->set_excitation(o_.chirp);
  arming_ = std::make_unique<ArmingPolicy>(ArmingSchedule::from(cfg_.supervision, cfg_.loop.rate_hz));
  if (o_.arm_at_start) loop_->set_policy(arming_.get());
  if (supervisor_->settings().pose_scheduled && !o_.pose_deg.empty() &&
      !cfg_.can) {  // the simulated robot stands at --pose
    const auto region = config::region_of(*cfg_.pose_schedule, o_.pose_deg.data(), o_.pose_deg.size());
    loop_->schedule(0, {rt::CommandKind::kSetPoseRegion, region ? static_cast<double>(*region) : -1.0});
  }
  if (Status s = configure_parameter_sets(); !s.ok()) return s;
  if (cfg_.spindle.job.empty()) return {};
  try {
    MachiningInputs in;
    in.active_set = [this] { return supervisor_->running_parameter_set(); };
    in.handing_over = [this] { return supervisor_->active_parameter_set() != supervisor_->running_parameter_set(); };
    in.on_advice = [this](const AdviceRecord& r) {  // the robot program reads it from modbus.robot.advice_register
      if (!modbus_ || r.status == AdviceStatus::kFollowed) return;
      if (r.status == AdviceStatus::kExpired)
        modbus_->withdraw_advice(r.seq);
      else
        modbus_->publish_advice(r.seq, r.advice.found, r.advice.found ? r.advice.options.front().rpm : 0.0,
                                r.advice.found ? r.advice.options.front().margin : 0.0);
    };
    in.robot_depth_mm = [this] { return modbus_ ? modbus_->robot_depth_mm() : std::nan(""); };
    if (cfg_.pose_schedule) {
      in.pose = milling::PoseDynamics{cfg_.pose_schedule->model_resolved, pose_schedule_.model,
                                      cfg_.pose_schedule->axis, cfg_.pose_schedule->modes};
      in.pose_deg = [this] { return robot_pose_deg(); };
      in.schedule = *cfg_.pose_schedule;
      if (path_ahead_) in.path_ahead_deg = [this] { return path_ahead_->poses_deg(); };
    }
    machining_ = std::make_unique<MachiningMonitor>(cfg_, set_configs_, std::move(in));
  } catch (const std::exception& e) {  // ConfigError, or a job file that does not parse
    return {StatusKind::kConfigError, std::string("spindle.job: ") + e.what()};
  }
  return {};
}

Status Cell::configure_devices() {
  if (cfg_.can) {
    can_ = std::make_unique<CanBus>(*cfg_.can, cfg_.loop.rate_hz, cfg_.loop.clock, o_.connect_timeout_s);
    modbus_ = std::make_unique<ModbusComponent>(
        *cfg_.modbus, cfg_.actuator.mounting,
        [this](config::Mounting m) {
          if (const auto set = parameter_set_for(m)) {
            if (!loop_->post({rt::CommandKind::kSelectParams, static_cast<double>(*set)}))
              spdlog::warn("the robot reports {} mounting: the command queue is full, selection dropped",
                           config::to_string(m));
          } else {
            spdlog::warn("the robot reports {} mounting and no parameter set is configured for it (parameter_sets)",
                         config::to_string(m));
          }
        },
        o_.connect_timeout_s);
    const auto& c = *cfg_.can;
    backend_name_ = "CAN " + c.interface + (c.fd ? " (FD)" : "") + ", Modbus amplifier " +
                    config::describe(cfg_.modbus->amplifier_link) +
                    (cfg_.modbus->robot_link ? ", robot " + config::describe(*cfg_.modbus->robot_link) : "");
  } else {
    config::Config plant_cfg = o_.plant_config ? *o_.plant_config : cfg_;
    if (cfg_.pose_schedule && !o_.pose_deg.empty())  // the robot model at the pose
      plant_cfg = analysis::config_at_pose(
          plant_cfg,
          analysis::pose_modes(pose_schedule_.model, o_.pose_deg, cfg_.pose_schedule->axis, cfg_.pose_schedule->modes));
    const bool own = o_.plant_config || (cfg_.pose_schedule && !o_.pose_deg.empty());
    const sim::PlantModel plant_model = own ? sim::build_plant_model(plant_cfg) : model_->plant();
    sim_ = std::make_unique<SimBackendComponent>(plant_model, plant_cfg, o_.backend);
    backend_name_ = "simulated plant";
  }
  const bool read_joints = !o_.pose_schedule_off || o_.watch_joints;
  const auto on_region = [this](std::optional<std::size_t> region) {
    if (!o_.pose_schedule_off) post_pose_region(region);  // watched only: no set follows the pose
  };
  if (cfg_.dds && cfg_.dds->joint_states && cfg_.pose_schedule && read_joints)
    joint_pose_ = std::make_unique<JointStatePose>(*cfg_.dds->joint_states, *cfg_.pose_schedule, on_region);
  if (cfg_.dds && cfg_.dds->path_ahead && cfg_.pose_schedule && !cfg_.spindle.job.empty())
    path_ahead_ = std::make_unique<PathAhead>(*cfg_.dds->path_ahead, cfg_.dds->path_ahead->names);
  if (cfg_.dds) {
    dds_ = std::make_unique<DdsEndpoint>(*cfg_.dds, cfg_.loop.rate_hz, cfg_.source, bridge_sources());
    spectrum_ = std::make_unique<SpectrumMonitor>(cfg_);
  }
  for (Component* c : components()) {
    if (Status s = c->configure(); !s.ok()) {
      for (Component* d : components())
        if (d->state() == LifecycleState::kInactive) (void)d->cleanup();
      return s;
    }
  }
  if (modbus_ && cfg_.modbus->robot.joints_register >= 0 && cfg_.pose_schedule && read_joints)
    modbus_->client().set_pose_callback(*cfg_.pose_schedule, on_region);
  if (modbus_ && cfg_.modbus->robot.spindle_rpm_register >= 0) {
    // The robot's spindle register: each settled speed (0 when the link is lost) becomes a set_spindle
    // command; the controller validates it against spindle.rpm_max.
    modbus_->client().set_spindle_callback([this](double rpm) {
      if (!loop_->post({rt::CommandKind::kSetSpindle, rpm}))
        spdlog::warn("the robot reports the spindle at {} rpm: the command queue is full, dropped", rpm);
    });
  }
  return {};
}

void Cell::configure_pose_sets() {
  for (std::size_t i = 1; i < pose_schedule_.regions.size(); ++i) {
    const auto& r = pose_schedule_.regions[i];
    const analysis::LoopModel m(r.config);
    supervisor_->add_parameter_set(
        {with_notch_speed_map(m), true, r.k_max_ns_per_m, delay_margin_s(m, r.config, r.k_max_ns_per_m)});
  }
}

Status Cell::configure_parameter_sets() {
  set_configs_.assign(1, pose_schedule_.regions.empty() ? cfg_ : pose_schedule_.regions.front().config);
  if (supervisor_->settings().pose_scheduled)
    for (std::size_t i = 1; i < pose_schedule_.regions.size(); ++i)
      set_configs_.push_back(pose_schedule_.regions[i].config);
  mounting_sets_.clear();
  mounting_sets_.emplace_back(cfg_.actuator.mounting, 0);
  try {
    if (const auto& speed = cfg_.controller.speed_schedule)  // the bands' controllers: sets 1..n, in order
      for (std::size_t i = 1; i <= speed->controllers.size(); ++i)
        (void)add_parameter_set(config::speed_controller_config(cfg_, i), false);
    for (const auto& ref : cfg_.parameter_sets) {
      const config::Config other = config::load_config_file(ref.resolved_path);
      if (other.loop.rate_hz != cfg_.loop.rate_hz)
        throw config::ConfigError(
            {{cfg_.source,
              {},
              "parameter_sets." + ref.mounting,
              "= '" + ref.path + "' runs at loop.rate_hz = " + std::to_string(other.loop.rate_hz) +
                  " Hz; every set must run at this configuration's " + std::to_string(cfg_.loop.rate_hz) + " Hz"}});
      if (other.controller.speed_schedule && !other.controller.speed_schedule->controllers.empty())
        throw config::ConfigError(
            {{cfg_.source,
              {},
              "parameter_sets." + ref.mounting,
              "= '" + ref.path +
                  "' schedules its controller by spindle speed "
                  "(controller.speed_schedule.controllers): a mounting's set may schedule K alone"}});
      const std::size_t idx = add_parameter_set(other, true);
      const auto mounting = ref.mounting == "vertical" ? config::Mounting::kVertical : config::Mounting::kHorizontal;
      std::erase_if(mounting_sets_, [&](const auto& p) { return p.first == mounting; });
      mounting_sets_.emplace_back(mounting, idx);
    }
    check_speed_bands(*supervisor_, set_configs_);
  } catch (const config::ConfigError& e) {
    for (Component* d : components()) (void)d->cleanup();
    return {StatusKind::kConfigError, e.what()};
  }
  return {};
}

std::size_t Cell::add_parameter_set(const config::Config& cfg, bool own_schedule) {
  const analysis::LoopModel m(cfg);
  set_configs_.push_back(cfg);
  const int polarity = cfg.controller.polarity;
  const auto k_max = analysis::max_stable_gain(m, polarity);
  control::ControllerParams p = with_notch_speed_map(m);
  // A mounting's own K schedule names set 0 for "this set"; a speed schedule's controllers carry the cell's.
  if (own_schedule) own_speed_bands(p, set_configs_.size() - 1);
  return supervisor_->add_parameter_set({p, m.stable(cfg.controller.gain_ns_per_m, polarity),
                                         k_max.value_or(control::kMaxGainNsPerM), delay_margin_s(m, cfg, k_max)});
}

std::optional<std::size_t> Cell::parameter_set_for(config::Mounting m) const {
  for (const auto& [mounting, idx] : mounting_sets_)
    if (mounting == m) return idx;
  return std::nullopt;
}

dds::Decision Cell::handle_request(dds::RequestKind kind, double value) {
  const CheckedRequest r = check_request(*supervisor_, cfg_, kind, value);
  if (!r.decision.accepted) return r.decision;
  if (kind == dds::RequestKind::kEnable) arming_->cancel();  // an operator has taken over arming
  if (!loop_->post(r.command)) return {false, "the loop's command queue is full: try again"};
  return r.decision;
}

void Cell::request_stop() noexcept {
  if (loop_) loop_->request_stop();
}

void Cell::on_frame(const rt::TelemetryFrame& f) {
  if (o_.on_frame) o_.on_frame(f);
  log_changes(f);
  if (std::isfinite(f.accel_mps2)) sum_sq_ += f.accel_mps2 * f.accel_mps2, ++n_samples_;
  summary_.peak_command_v = std::max(summary_.peak_command_v, std::abs(f.command_v));
  TripTiming& tt = summary_.trip_timing;
  if (tt.trip_s >= 0.0 && f.trip == 0) tt = TripTiming{};  // recovered: the timing is the next trip's (the run's own)
  if (tt.trip_s < 0.0 && (f.flags & rt::kFlagFresh)) tt.last_fresh_s = f.time_s, last_fresh_frame_ = n_frames_;
  if (tt.trip_s < 0.0 && f.trip != 0) tt.trip_s = f.time_s;
  if (tt.trip_s >= 0.0 && tt.safe_s < 0.0 && f.command_v == 0.0 && !(f.flags & rt::kFlagAmplifierEnable)) {
    tt.safe_s = f.time_s;
    tt.ticks_to_safe = n_frames_ - last_fresh_frame_;
  }
  if (availability_) availability_->on_frame(f);
  ++n_frames_;
  if (o_.keep_frames) frames_.push_back(f);
}

Status Cell::activate(double duration_s) {
  if (state_ != LifecycleState::kInactive)
    return {StatusKind::kWrongState, std::string("cell: cannot activate while ") + to_string(state_) +
                                         " (configure first; a cell runs once per configuration)"};
  if (loop_->stats().ticks_run > 0) return {StatusKind::kWrongState, "cell: this configuration has run already"};
  summary_ = {};
  summary_.config = cfg_.source;
  summary_.clock = config::to_string(cfg_.loop.clock);
  summary_.rate_hz = cfg_.loop.rate_hz;
  summary_.duration_s = duration_s;
  summary_.backend = backend_name_;
  summary_.analysis_stable = stable_;
  summary_.max_stable_gain_ns_per_m = max_stable_gain_.value_or(control::kMaxGainNsPerM);
  summary_.arming.enabled = o_.arm_at_start;
  summary_.arming.deadline_s = cfg_.supervision.arm_deadline_s;
  sum_sq_ = 0.0;
  n_samples_ = 0;
  n_frames_ = 0;
  availability_.emplace(cfg_.loop.rate_hz, cfg_.controller.gain_ramp_s);
  last_fresh_frame_ = -1;
  frames_.clear();
  const bool wall = cfg_.loop.clock == config::ClockKind::kWall;
  if (o_.impact_every_s > 0.0 && sim_) {
    std::vector<double> hits;
    for (double t = o_.impact_every_s; t < duration_s; t += o_.impact_every_s) hits.push_back(t);
    sim_->plant().add_excitation(
        std::make_unique<sim::ImpactHammer>(0, cfg_.bench.impact_peak_n, cfg_.bench.impact_duration_ms * 1e-3, hits));
  }
  try {
    if (!o_.record_path.empty())
      recorder_ = std::make_unique<rt::Recorder>(
          o_.record_path, rt::recording_header({cfg_.loop.rate_hz, cfg_.source, cfg_.yaml_text}, *supervisor_,
                                               cfg_.loop.clock, loop_->excitation()));
  } catch (const std::exception& e) {
    return {StatusKind::kDeviceError, std::string("--record: ") + e.what()};
  }
  if (wall && o_.realtime_setup) rt_process_.emplace(cfg_.realtime, summary_.realtime);
  std::vector<rt::TelemetryDrain::Consumer> consumers;
  if (recorder_) consumers.emplace_back([this](const rt::TelemetryFrame& f) { recorder_->write(f); });
  consumers.emplace_back([this](const rt::TelemetryFrame& f) { on_frame(f); });
  if (dds_) consumers.emplace_back([this](const rt::TelemetryFrame& f) { dds_->bridge().on_frame(f); });
  if (machining_) consumers.emplace_back([this](const rt::TelemetryFrame& f) { machining_->on_frame(f); });
  if (spectrum_) consumers.emplace_back([this](const rt::TelemetryFrame& f) { spectrum_->on_frame(f); });
  drain_ = std::make_unique<rt::TelemetryDrain>(*ring_, std::move(consumers));
  drain_->start();
  state_ = LifecycleState::kActive;  // from here on deactivate() undoes whatever was started
  for (Component* c : components()) {
    if (Status s = c->activate(); !s.ok()) {
      (void)deactivate();
      return s;
    }
  }
  const auto ticks = static_cast<std::uint64_t>(std::llround(duration_s * cfg_.loop.rate_hz));
  loop_thread_ = std::thread([this, wall, ticks] {
    if (wall && o_.realtime_setup) rt::setup_realtime_thread(cfg_.realtime, summary_.realtime);
    loop_->run(ticks);
  });
  return {};
}

void Cell::wait() {
  if (loop_thread_.joinable()) loop_thread_.join();
}

Status Cell::deactivate() {
  if (state_ != LifecycleState::kActive)
    return {StatusKind::kWrongState, std::string("cell: cannot deactivate while ") + to_string(state_)};
  if (loop_thread_.joinable()) {
    loop_->request_stop();  // no-op if the run already ended: the loop only returns once safe
    loop_thread_.join();
  }
  drain_->stop();
  Status result;
  // The amplifier goes off (Modbus) after the loop has ramped the command to zero and disabled it.
  for (Component* c : components()) {
    if (c->state() != LifecycleState::kActive) continue;
    if (Status s = c->deactivate(); !s.ok() && result.ok()) result = s;
  }
  finish_summary();
  drain_.reset();
  recorder_.reset();
  rt_process_.reset();
  state_ = LifecycleState::kInactive;
  return result;
}

void Cell::finish_summary() {
  RunSummary& s = summary_;
  if (dds_) s.dds = dds_->bridge().counters();
  if (modbus_) s.modbus = modbus_->client().counters();
  if (joint_pose_) s.joint_states = joint_pose_->counters();
  if (path_ahead_) s.path_ahead = path_ahead_->counters();
  if (can_) s.can = can_->driver().counters();
  if (recorder_) {
    recorder_->close();
    s.recorded_frames = recorder_->frames();
    s.record_errors = recorder_->write_errors();
    s.record_path = recorder_->path();
  }
  s.loop = loop_->stats();
  s.supervisor = supervisor_->counters();
  s.events.assign(supervisor_->events(), supervisor_->events() + supervisor_->events_logged());
  s.events_total = supervisor_->events_total();
  s.spindle_rpm = supervisor_->controller().spindle_rpm();
  const control::ControllerParams& cp = supervisor_->controller().params();
  s.speed_bands = cp.speed_band_count;
  if (const std::size_t band = cp.speed_band_of(supervisor_->controller().schedule_rpm()); band < cp.speed_band_count)
    s.speed_band = band;
  s.gain_ns_per_m = supervisor_->controller().target_gain_ns_per_m();
  s.notch_centre_hz =
      supervisor_->controller().notches().settings().enabled ? supervisor_->controller().notches().centre_hz() : 0.0;
  s.final_state = rt::to_string(supervisor_->state());
  s.active_parameter_set = supervisor_->active_parameter_set();
  s.trip = rt::to_string(supervisor_->latched_trip());
  s.trip_description = rt::describe(supervisor_->latched_trip());
  s.arming.outcome = arming_->outcome();
  s.arming.attempts = arming_->attempts();
  s.arming.last_refusal = arming_->last_refusal();
  s.telemetry_frames = drain_->frames();
  if (availability_) s.availability = availability_->result();
  s.sensor_rms_mps2 = n_samples_ ? std::sqrt(sum_sq_ / static_cast<double>(n_samples_)) : 0.0;
  if (machining_) {
    s.machining = machining_->settled_sample(kMachiningSummaryWaitS);
    s.advice = machining_->advice();
    machining_->complete_trail(kMachiningSummaryWaitS);
    s.limits_trail = machining_->trail();
  }
}

Status Cell::cleanup() {
  if (state_ != LifecycleState::kInactive)
    return {StatusKind::kWrongState, std::string("cell: cannot clean up while ") + to_string(state_)};
  release();
  state_ = LifecycleState::kUnconfigured;
  return {};
}

// What configure built, released in the reverse order: cleanup()'s work and configure()'s rollback.
void Cell::release() {
  // First the machining monitor: its advisor's thread writes to the Modbus client and reads the robot's
  // depth from it (a run that ended under load crashed there when the client went first).
  machining_.reset();
  for (Component* c : components())
    if (c->state() == LifecycleState::kInactive) (void)c->cleanup();
  // The DDS endpoint before the loop: its listeners (a parameter request, a joint state) post to the loop.
  dds_.reset();
  joint_pose_.reset();
  path_ahead_.reset();
  loop_.reset();
  arming_.reset();
  ring_.reset();
  supervisor_.reset();
  sim_.reset();
  can_.reset();
  modbus_.reset();
  spectrum_.reset();
  model_.reset();
  mounting_sets_.clear();
  pose_schedule_ = {};
  set_configs_.clear();
}

Status Cell::run(double duration_s) {
  if (Status s = activate(duration_s); !s.ok()) return s;
  wait();
  if (Status s = deactivate(); !s.ok()) spdlog::warn("{}", s.message);
  return {};
}

sim::Plant& Cell::plant() {
  if (!sim_) throw std::logic_error("the cell runs the " + backend_name_ + " backend: it has no simulated plant");
  return sim_->plant();
}

drivers::SimBackend& Cell::sim_backend() {
  if (!sim_) throw std::logic_error("the cell runs the " + backend_name_ + " backend: it has no simulated backend");
  return sim_->backend();
}

}  // namespace robodamp::runtime
