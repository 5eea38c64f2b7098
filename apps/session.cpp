#include "apps/session.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

#include "rt/signals.hpp"

#include <spdlog/spdlog.h>

namespace robodamp::apps {

Session::Session(const config::Config& cfg, const SessionOptions& o) : cfg_(cfg), o_(o) {
  if (o_.clock) cfg_.loop.clock = *o_.clock;
  model_ = std::make_unique<analysis::LoopModel>(cfg_);
  const int polarity = cfg_.controller.polarity;
  stable_ = model_->stable(cfg_.controller.gain_ns_per_m, polarity);
  max_stable_gain_ = analysis::max_stable_gain(*model_, polarity);

  if (cfg_.can.has_value() != cfg_.modbus.has_value())
    throw config::ConfigError({{cfg_.source, {}, cfg_.can ? "modbus" : "can",
                                "missing: a hardware session needs both the can section (sensor and command frames) and "
                                "the modbus section (the amplifier's enable and status)"}});
  if (cfg_.can) {
    const auto& c = *cfg_.can;
    can_ = std::make_unique<drivers::CanDriver>(
        c, drivers::CanChannel::open(c.interface, c.fd, c.sensor.id, c.sensor.extended_id, o_.connect_timeout_s),
        cfg_.loop.rate_hz);
    // Lockstep with the emulator: a missing frame waits up to this long, then counts towards the stale trip.
    if (cfg_.loop.clock == config::ClockKind::kVirtual) can_->set_lockstep_wait(1.0);
    else can_->set_dejitter(true);
    modbus_ = std::make_unique<drivers::ModbusSupervisor>(*cfg_.modbus, cfg_.actuator.mounting, [this](config::Mounting m) {
      if (const auto set = parameter_set_for(m)) {
        if (!loop_->post({rt::CommandKind::kSelectParams, static_cast<double>(*set)}))
          spdlog::warn("the robot reports {} mounting: the command queue is full, selection dropped", config::to_string(m));
      } else {
        spdlog::warn("the robot reports {} mounting and no parameter set is configured for it (parameter_sets)",
                     config::to_string(m));
      }
    });
    sensor_ = can_.get();
    actuator_ = can_.get();
    io_ = modbus_.get();
    backend_name_ = "CAN " + c.interface + (c.fd ? " (FD)" : "") + ", Modbus amplifier " +
                    config::describe(cfg_.modbus->amplifier_link) +
                    (cfg_.modbus->robot_link ? ", robot " + config::describe(*cfg_.modbus->robot_link) : "");
  } else {
    const config::Config& plant_cfg = o_.plant_config ? *o_.plant_config : cfg_;
    const sim::PlantModel plant_model = o_.plant_config ? sim::build_plant_model(plant_cfg) : model_->plant();
    plant_ = std::make_unique<sim::Plant>(plant_model, plant_cfg);
    if (plant_cfg.disturbances.drives_on) plant_->add_excitation(sim::make_drive_vibration(plant_model, plant_cfg));
    backend_ = std::make_unique<drivers::SimBackend>(*plant_, o_.backend);
    sensor_ = backend_.get();
    actuator_ = backend_.get();
    io_ = backend_.get();
    backend_name_ = "simulated plant";
  }
  const double k_max = max_stable_gain_.value_or(control::kMaxGainNsPerM);
  supervisor_ = std::make_unique<rt::Supervisor>(rt::supervisor_settings(cfg_, stable_, k_max), model_->chain().params);
  ring_ = std::make_unique<rt::SpscRing<rt::TelemetryFrame>>(static_cast<std::size_t>(cfg_.telemetry.ring_frames));
  loop_ = std::make_unique<rt::Loop>(cfg_.loop.rate_hz, cfg_.loop.clock, *supervisor_, *sensor_, *actuator_, *io_,
                                     ring_.get());
  mounting_sets_.emplace_back(cfg_.actuator.mounting, 0);
  for (const auto& ref : cfg_.parameter_sets) {
    const config::Config other = config::load_config_file(ref.resolved_path);
    if (other.loop.rate_hz != cfg_.loop.rate_hz)
      throw config::ConfigError({{cfg_.source, {}, "parameter_sets." + ref.mounting,
                                  "= '" + ref.path + "' runs at loop.rate_hz = " + std::to_string(other.loop.rate_hz) +
                                      " Hz; every set must run at this configuration's " +
                                      std::to_string(cfg_.loop.rate_hz) + " Hz"}});
    const std::size_t idx = add_parameter_set(other);
    const auto mounting = ref.mounting == "vertical" ? config::Mounting::kVertical : config::Mounting::kHorizontal;
    std::erase_if(mounting_sets_, [&](const auto& p) { return p.first == mounting; });
    mounting_sets_.emplace_back(mounting, idx);
  }
  if (o_.arm_at_start)
    loop_->schedule(static_cast<std::uint64_t>(cfg_.supervision.arming_live_cycles) + 1, {rt::CommandKind::kArm, 0.0});
}

Session::~Session() = default;

dds::Decision Session::handle_request(dds::RequestKind kind, double value) {
  char b[256];
  rt::OperatorCommand c;
  std::string what;
  switch (kind) {
    case dds::RequestKind::kSetGain: {
      const std::size_t set = supervisor_->active_parameter_set();
      const double limit = std::min(supervisor_->gain_limit_ns_per_m(), control::kMaxGainNsPerM);
      std::snprintf(b, sizeof b, "supervision.max_gain_fraction = %g x the analysed maximum stable K of parameter set %zu",
                    cfg_.supervision.max_gain_fraction, set);
      if (auto problem = config::gain_request_problem(value, limit, b)) return {false, *problem};
      c = {rt::CommandKind::kSetGain, value};
      std::snprintf(b, sizeof b, "K ramps to %g N s/m over controller.gain_ramp_s = %g s", value, cfg_.controller.gain_ramp_s);
      what = b;
      break;
    }
    case dds::RequestKind::kSelectParameterSet: {
      const auto& sets = supervisor_->parameter_sets();
      if (!(value >= 0.0 && value == std::floor(value) && value < static_cast<double>(sets.size()))) {
        std::snprintf(b, sizeof b, "parameter_set = %g is not a configured set: allowed 0 <= value <= %zu (0 = %s, then parameter_sets)",
                      value, sets.size() - 1, cfg_.source.c_str());
        return {false, b};
      }
      const auto idx = static_cast<std::size_t>(value);
      if (!sets[idx].analysis_stable) return {false, "parameter set " + std::to_string(idx) + ": the analysis finds its loop unstable"};
      c = {rt::CommandKind::kSelectParams, value};
      what = "parameter set " + std::to_string(idx) + " is handed over at the next tick (fade out, swap, fade in)";
      break;
    }
    case dds::RequestKind::kEnable:
      if (value != 0.0 && value != 1.0) {
        std::snprintf(b, sizeof b, "enable = %g is out of range: allowed 0 (disarm) or 1 (arm)", value);
        return {false, b};
      }
      c = {value == 1.0 ? rt::CommandKind::kArm : rt::CommandKind::kDisarm, 0.0};
      what = value == 1.0 ? "arming: the supervisor checks the sensor, the actuator path and the analysis at the next tick "
                            "(the status topic shows the outcome)"
                          : "disarming: the command fades out over controller.gain_ramp_s";
      break;
  }
  if (!loop_->post(c)) return {false, "the loop's command queue is full: try again"};
  return {true, what};
}

std::optional<std::size_t> Session::parameter_set_for(config::Mounting m) const {
  for (const auto& [mounting, idx] : mounting_sets_)
    if (mounting == m) return idx;
  return std::nullopt;
}

std::size_t Session::add_parameter_set(const config::Config& cfg) {
  const analysis::LoopModel m(cfg);
  const int polarity = cfg.controller.polarity;
  const auto k_max = analysis::max_stable_gain(m, polarity);
  return supervisor_->add_parameter_set({m.chain().params, m.stable(cfg.controller.gain_ns_per_m, polarity),
                                         k_max.value_or(control::kMaxGainNsPerM)});
}

RunSummary Session::run(double duration_s) {
  RunSummary s;
  s.config = cfg_.source;
  s.clock = config::to_string(cfg_.loop.clock);
  s.rate_hz = cfg_.loop.rate_hz;
  s.duration_s = duration_s;
  s.analysis_stable = stable_;
  s.max_stable_gain_ns_per_m = max_stable_gain_.value_or(control::kMaxGainNsPerM);
  const bool wall = cfg_.loop.clock == config::ClockKind::kWall;
  const auto ticks = static_cast<std::uint64_t>(std::llround(duration_s * cfg_.loop.rate_hz));

  if (o_.impact_every_s > 0.0 && plant_) {
    std::vector<double> hits;
    for (double t = o_.impact_every_s; t < duration_s; t += o_.impact_every_s) hits.push_back(t);
    plant_->add_excitation(std::make_unique<sim::ImpactHammer>(0, cfg_.bench.impact_peak_n,
                                                               cfg_.bench.impact_duration_ms * 1e-3, hits));
  }

  std::optional<rt::RealtimeProcess> rt_process;
  if (wall && o_.realtime_setup) rt_process.emplace(cfg_.realtime, s.realtime);
  std::unique_ptr<rt::Recorder> recorder;
  if (!o_.record_path.empty())
    recorder = std::make_unique<rt::Recorder>(o_.record_path, rt::recording_header(cfg_, *supervisor_, cfg_.loop.clock));

  s.backend = backend_name_;
  if (modbus_) {
    modbus_->start();
    if (!modbus_->wait_for_amplifier(std::chrono::duration<double>(o_.connect_timeout_s)))
      spdlog::warn("Modbus: no answer from the amplifier ({}) within {} s; arming will wait for it",
                   config::describe(cfg_.modbus->amplifier_link), o_.connect_timeout_s);
  }
  double sum_sq = 0.0, peak = 0.0;
  std::uint64_t n = 0;
  TripTiming& tt = s.trip_timing;
  // Hardware: arming is retried every 0.5 s while the loop is disabled (the sensor may not be live yet at
  // the first attempt), until it has been active once; the run's end and a trip are never re-armed.
  const bool retry_arm = can_ && o_.arm_at_start;
  bool was_active = false;
  double next_arm_s = 0.5;
  frames_.clear();
  std::vector<rt::TelemetryDrain::Consumer> consumers;
  if (recorder) consumers.emplace_back([&recorder](const rt::TelemetryFrame& f) { recorder->write(f); });
  consumers.emplace_back([&](const rt::TelemetryFrame& f) {
    if (std::isfinite(f.accel_mps2)) sum_sq += f.accel_mps2 * f.accel_mps2, ++n;
    peak = std::max(peak, std::abs(f.command_v));
    if (retry_arm && !was_active) {
      if (f.state == static_cast<std::uint8_t>(rt::State::kActive)) {
        was_active = true;
      } else if (f.state == static_cast<std::uint8_t>(rt::State::kDisabled) && f.time_s >= next_arm_s &&
                 f.time_s < duration_s - 1.0) {
        (void)loop_->post({rt::CommandKind::kArm, 0.0});
        next_arm_s = f.time_s + 0.5;
      }
    }
    if (tt.trip_s < 0.0 && (f.flags & rt::kFlagFresh)) tt.last_fresh_s = f.time_s;
    if (tt.trip_s < 0.0 && f.trip != 0) tt.trip_s = f.time_s;
    if (tt.trip_s >= 0.0 && tt.safe_s < 0.0 && f.command_v == 0.0 && !(f.flags & rt::kFlagAmplifierEnable))
      tt.safe_s = f.time_s;
    if (keep_frames_) frames_.push_back(f);
  });
  std::unique_ptr<dds::Bridge> bridge;
  if (cfg_.dds) {
    bridge = std::make_unique<dds::Bridge>(
        *cfg_.dds, cfg_.loop.rate_hz, cfg_.source,
        dds::BridgeSources{backend_name_, [this] { return supervisor_->active_parameter_set(); },
                           [this] { return std::min(supervisor_->gain_limit_ns_per_m(), control::kMaxGainNsPerM); },
                           [this](dds::RequestKind k, double v) { return handle_request(k, v); }});
    consumers.emplace_back([&bridge](const rt::TelemetryFrame& f) { bridge->on_frame(f); });
    bridge->start();
    spdlog::info("DDS: domain {} ({}), telemetry {} Hz, status {} Hz, parameter writes {}", cfg_.dds->domain_id,
                 config::to_string(cfg_.dds->transport), cfg_.dds->telemetry_rate_hz, cfg_.dds->status_rate_hz,
                 cfg_.dds->parameter_writes ? "on" : "off");
  }
  rt::TelemetryDrain drain(*ring_, std::move(consumers));
  drain.start();
  if (can_ && wall) {
    if (const auto stale = can_->flush()) spdlog::info("CAN: {} frames queued before the loop started, discarded", stale);
  }
  std::thread thread([&] {
    if (wall && o_.realtime_setup) rt::setup_realtime_thread(cfg_.realtime, s.realtime);
    loop_->run(ticks);
  });
  thread.join();
  drain.stop();
  if (bridge) {
    bridge->stop();
    s.dds = bridge->counters();
  }
  if (modbus_) {
    modbus_->stop();
    s.modbus = modbus_->counters();
  }
  if (can_) s.can = can_->counters();
  if (recorder) {
    recorder->close();
    s.recorded_frames = recorder->frames();
    s.record_errors = recorder->write_errors();
    s.record_path = recorder->path();
  }
  s.loop = loop_->stats();
  s.supervisor = supervisor_->counters();
  s.final_state = rt::to_string(supervisor_->state());
  s.trip = rt::to_string(supervisor_->latched_trip());
  s.trip_description = rt::describe(supervisor_->latched_trip());
  s.telemetry_frames = drain.frames();
  s.sensor_rms_mps2 = n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0;
  s.peak_command_v = peak;
  return s;
}

nlohmann::json summary_json(const RunSummary& s) {
  using nlohmann::json;
  auto hist = [](const rt::TimingHistogram& h) {
    return json{{"count", h.count()},           {"p50_us", h.percentile_us(0.5)}, {"p99_us", h.percentile_us(0.99)},
                {"p999_us", h.percentile_us(0.999)}, {"max_us", h.max_us()},       {"mean_us", h.mean_us()}};
  };
  json trips = json::object();
  for (std::size_t i = 1; i < rt::kTripCount; ++i)
    trips[rt::to_string(static_cast<rt::Trip>(i))] = s.supervisor.trips[i];
  const auto ticks = static_cast<double>(std::max<std::uint64_t>(1, s.loop.ticks_run + s.loop.missed_ticks));
  json j = {{"config", s.config},
          {"clock", s.clock},
          {"rate_hz", s.rate_hz},
          {"duration_s", s.duration_s},
          {"elapsed_s", s.loop.elapsed_s},
          {"final_state", s.final_state},
          {"trip", s.trip},
          {"trip_description", s.trip_description},
          {"analysis_stable", s.analysis_stable},
          {"max_stable_gain_ns_per_m", s.max_stable_gain_ns_per_m},
          {"ticks_run", s.loop.ticks_run},
          {"missed_ticks", s.loop.missed_ticks},
          {"overruns", s.loop.overruns},
          {"overrun_pct", 100.0 * static_cast<double>(s.loop.overruns) / ticks},
          {"wake_latency", hist(s.loop.wake_latency)},
          {"compute", hist(s.loop.compute)},
          {"telemetry", {{"frames", s.telemetry_frames}, {"ring_drops", s.loop.ring_drops}, {"ring_waits", s.loop.ring_waits}}},
          {"recording", {{"path", s.record_path}, {"frames", s.recorded_frames}, {"write_errors", s.record_errors}}},
          {"supervisor",
           {{"trips", trips},
            {"stale_ticks", s.supervisor.stale_ticks},
            {"invalid_samples", s.supervisor.invalid_samples},
            {"saturated_ticks", s.supervisor.saturated_ticks},
            {"arm_refused", s.supervisor.arm_refused},
            {"gain_refused", s.supervisor.gain_refused},
            {"params_selected", s.supervisor.params_selected},
            {"params_refused", s.supervisor.params_refused}}},
          {"realtime",
           {{"memory_locked", s.realtime.memory_locked},
            {"sched_fifo", s.realtime.fifo},
            {"priority", s.realtime.priority},
            {"affinity", s.realtime.affinity},
            {"timer_slack_1ns", s.realtime.timer_slack},
            {"cpu_dma_latency_held", s.realtime.dma_latency_held},
            {"warnings", s.realtime.warnings}}},
          {"sensor_rms_mps2", s.sensor_rms_mps2},
          {"peak_command_v", s.peak_command_v}};
  j["backend"] = s.backend;
  auto t = [](double v) { return v >= 0.0 ? json(v) : json(nullptr); };
  j["trip_timing"] = {{"last_fresh_s", t(s.trip_timing.last_fresh_s)},
                      {"trip_s", t(s.trip_timing.trip_s)},
                      {"safe_s", t(s.trip_timing.safe_s)}};
  if (s.can) {
    const auto& c = *s.can;
    j["can"] = {{"rx_frames", c.rx_frames},       {"rx_other", c.rx_other},     {"rx_malformed", c.rx_malformed},
                {"lost_frames", c.lost_frames},   {"stale_frames", c.stale_frames}, {"error_frames", c.error_frames},
                {"bus_off", c.bus_off},           {"restarts", c.restarts},     {"rx_errors", c.rx_errors},
                {"tx_frames", c.tx_frames},       {"tx_queue_full", c.tx_queue_full}, {"tx_errors", c.tx_errors},
                {"tx_skipped", c.tx_skipped},     {"tx_clipped", c.tx_clipped}, {"rx_held", c.rx_held},
                {"rx_skipped", c.rx_skipped}};
  }
  if (s.dds) j["dds"] = {{"telemetry", s.dds->telemetry}, {"status", s.dds->status}, {"requests", s.dds->requests},
                         {"refused", s.dds->refused}};
  if (s.modbus) {
    const auto& m = *s.modbus;
    j["modbus"] = {{"amplifier_polls", m.amplifier_polls}, {"robot_polls", m.robot_polls},
                   {"connects", m.connects},               {"connect_failures", m.connect_failures},
                   {"errors", m.errors},                   {"timeouts", m.timeouts},
                   {"link_faults", m.link_faults},         {"coil_writes", m.coil_writes},
                   {"mounting_changes", m.mounting_changes}, {"mounting_unknown", m.mounting_unknown}};
  }
  return j;
}

std::string summary_text(const RunSummary& s) {
  std::ostringstream os;
  char b[256];
  const auto& st = s.loop;
  const double all = static_cast<double>(std::max<std::uint64_t>(1, st.ticks_run + st.missed_ticks));
  std::snprintf(b, sizeof b, "robodamp run: %s, %s, %s clock, %.0f Hz, %.3f s (%.3f s elapsed)\n",
                s.config.c_str(), s.backend.c_str(), s.clock.c_str(), s.rate_hz, s.duration_s, st.elapsed_s);
  os << b;
  if (s.clock == "wall") {
    os << "  real time: " << (s.realtime.fifo ? "SCHED_FIFO " + std::to_string(s.realtime.priority) : "SCHED_OTHER")
       << (s.realtime.memory_locked ? ", memory locked" : "") << (s.realtime.dma_latency_held ? ", cpu_dma_latency 0" : "")
       << (s.realtime.timer_slack ? ", timer slack 1 ns" : "") << (s.realtime.affinity ? ", pinned" : "") << '\n';
  }
  os << "  state: " << s.final_state;
  if (s.trip != "none") os << "  (tripped: " << s.trip << " - " << s.trip_description << ")";
  os << '\n';
  std::snprintf(b, sizeof b, "  ticks %llu, missed %llu, overruns %llu (%.4f %%)\n",
                static_cast<unsigned long long>(st.ticks_run), static_cast<unsigned long long>(st.missed_ticks),
                static_cast<unsigned long long>(st.overruns), 100.0 * static_cast<double>(st.overruns) / all);
  os << b;
  if (s.clock == "wall") {
    const auto& h = st.wake_latency;
    std::snprintf(b, sizeof b, "  wake-up latency: p50 %.0f us, p99 %.0f us, p99.9 %.0f us, max %.1f us\n",
                  h.percentile_us(0.5), h.percentile_us(0.99), h.percentile_us(0.999), h.max_us());
    os << b;
  }
  std::snprintf(b, sizeof b, "  compute per tick: mean %.2f us, p99 %.0f us, max %.1f us\n", st.compute.mean_us(),
                st.compute.percentile_us(0.99), st.compute.max_us());
  os << b;
  std::string trips;
  for (std::size_t i = 1; i < rt::kTripCount; ++i)
    if (s.supervisor.trips[i] > 0)
      trips += std::string(trips.empty() ? "" : ", ") + rt::to_string(static_cast<rt::Trip>(i)) + " " +
               std::to_string(s.supervisor.trips[i]);
  std::snprintf(b, sizeof b, "  supervisor: stale %llu, invalid %llu, saturated %llu ticks, arm refused %llu, gain refused %llu; trips: %s\n",
                static_cast<unsigned long long>(s.supervisor.stale_ticks),
                static_cast<unsigned long long>(s.supervisor.invalid_samples),
                static_cast<unsigned long long>(s.supervisor.saturated_ticks),
                static_cast<unsigned long long>(s.supervisor.arm_refused),
                static_cast<unsigned long long>(s.supervisor.gain_refused), trips.empty() ? "none" : trips.c_str());
  os << b;
  std::snprintf(b, sizeof b, "  vibration at the sensor: %.4f m/s^2 RMS; peak command %.3f V; K_max %.0f N s/m\n",
                s.sensor_rms_mps2, s.peak_command_v, s.max_stable_gain_ns_per_m);
  os << b;
  std::snprintf(b, sizeof b, "  telemetry: %llu frames, %llu dropped", static_cast<unsigned long long>(s.telemetry_frames),
                static_cast<unsigned long long>(st.ring_drops));
  os << b;
  if (!s.record_path.empty())
    os << "; recorded " << s.recorded_frames << " frames to " << s.record_path
       << (s.record_errors ? " (" + std::to_string(s.record_errors) + " write errors)" : "");
  os << '\n';
  if (s.can) {
    const auto& c = *s.can;
    std::snprintf(b, sizeof b,
                  "  CAN: %llu sensor frames (%llu lost, %llu stale, %llu malformed, %llu other ids), %llu error frames, "
                  "%llu bus-off, %llu held over / %llu skipped (de-jitter); %llu commands sent (%llu queue full, %llu errors, "
                  "%llu skipped)\n",
                  static_cast<unsigned long long>(c.rx_frames), static_cast<unsigned long long>(c.lost_frames),
                  static_cast<unsigned long long>(c.stale_frames), static_cast<unsigned long long>(c.rx_malformed),
                  static_cast<unsigned long long>(c.rx_other), static_cast<unsigned long long>(c.error_frames),
                  static_cast<unsigned long long>(c.bus_off), static_cast<unsigned long long>(c.rx_held),
                  static_cast<unsigned long long>(c.rx_skipped), static_cast<unsigned long long>(c.tx_frames),
                  static_cast<unsigned long long>(c.tx_queue_full), static_cast<unsigned long long>(c.tx_errors),
                  static_cast<unsigned long long>(c.tx_skipped));
    os << b;
  }
  if (s.modbus) {
    const auto& m = *s.modbus;
    std::snprintf(b, sizeof b,
                  "  Modbus: %llu amplifier and %llu robot polls, %llu connects (%llu failed), %llu errors (%llu timeouts), "
                  "%llu link faults, %llu mounting changes\n",
                  static_cast<unsigned long long>(m.amplifier_polls), static_cast<unsigned long long>(m.robot_polls),
                  static_cast<unsigned long long>(m.connects), static_cast<unsigned long long>(m.connect_failures),
                  static_cast<unsigned long long>(m.errors), static_cast<unsigned long long>(m.timeouts),
                  static_cast<unsigned long long>(m.link_faults), static_cast<unsigned long long>(m.mounting_changes));
    os << b;
  }
  if (s.dds) {
    std::snprintf(b, sizeof b, "  DDS: %llu telemetry and %llu status samples published; %llu parameter requests (%llu refused)\n",
                  static_cast<unsigned long long>(s.dds->telemetry), static_cast<unsigned long long>(s.dds->status),
                  static_cast<unsigned long long>(s.dds->requests), static_cast<unsigned long long>(s.dds->refused));
    os << b;
  }
  if (s.trip_timing.trip_s >= 0.0) {
    std::snprintf(b, sizeof b, "  trip at %.4f s (last fresh sample %.4f s), safe at %.4f s\n", s.trip_timing.trip_s,
                  s.trip_timing.last_fresh_s, s.trip_timing.safe_s);
    os << b;
  }
  if (!s.realtime.warnings.empty())
    os << "  real-time set-up: " << s.realtime.warnings.size() << " step(s) fell back (warnings at start)\n";
  return os.str();
}

}  // namespace robodamp::apps
