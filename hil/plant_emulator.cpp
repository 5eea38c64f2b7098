#include "hil/plant_emulator.hpp"
#include "hil/plant_emulator_class.hpp"

#include <linux/can/error.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "analysis/bench_run.hpp"
#include "drivers/can_channel.hpp"
#include "drivers/can_codec.hpp"
#include "hil/emulator_registers.hpp"
#include "rt/clock.hpp"
#include "rt/realtime.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::hil {

namespace {

constexpr double kSilentControllerS = 10.0;  // lockstep: no command for this long ends the run
constexpr double kTemperatureTauS = 10.0;    // amplifier heating time constant
constexpr double kAdvicePollS = 0.01;        // how often the robot program reads the advice block (plant time)

}  // namespace

namespace detail {

sim::Plant make_plant(const config::Config& cfg, const sim::PlantModel& model) {
  sim::Plant plant(model, cfg);
  if (cfg.disturbances.drives_on) plant.add_excitation(sim::make_drive_vibration(model, cfg));
  return plant;
}

const config::CanConfig& can_section(const config::Config& cfg) {
  if (!cfg.can || !cfg.modbus)
    throw config::ConfigError(
        {{cfg.source,
          {},
          cfg.can ? "modbus" : "can",
          cfg.can ? "missing: the emulator serves the amplifier's registers from the modbus section"
                  : "missing: the emulator sends and receives the frames of the can section"}});
  return *cfg.can;
}

PlantEmulator::PlantEmulator(const config::Config& cfg, const EmulatorOptions& o)
    : cfg_(cfg),
      o_(o),
      can_(can_section(cfg)),
      pacing_(o.pacing.value_or(cfg.hil.pacing)),
      fs_(cfg.loop.rate_hz),
      dt_(1.0 / cfg.loop.rate_hz),
      trajectory_(o.pose_trajectory.empty() ? std::nullopt
                                            : std::make_optional<PoseTrajectory>(cfg, o.pose_trajectory)),
      model_(trajectory_ ? trajectory_->plant_at(trajectory_->at(0.0)) : sim::build_plant_model(cfg)),
      plant_(make_plant(cfg, model_)),
      impact_id_(o.impact_location > 0 ? o.impact_location
                                       : (cfg.robot.frfs.empty() ? 1 : cfg.robot.frfs.front().excitation_location)),
      impact_index_(model_.index_of(impact_id_)),
      test_{impact_index_, cfg.bench.impact_peak_n,      cfg.bench.impact_duration_ms,
            true,          cfg.controller.gain_ns_per_m, cfg.controller.polarity},
      regs_(cfg),
      temperature_c_(cfg.hil.ambient_c) {
  rep_.config = cfg.source;
  rep_.pacing = config::to_string(pacing_);
  rep_.transport = can_.interface;
  rep_.impact_location = model_.locations[impact_index_].name + " (location " + std::to_string(impact_id_) + ")";
  rep_.records_planned = o.impacts && o.measure_out.empty() ? cfg.bench.averages : 0;
  setup_cut();
  rep_.modbus = regs_.describe();
  regs_.set_temperature(cfg.hil.ambient_c);
  check_measure_dwells();
  if (trajectory_) {
    regs_.set_joints(trajectory_->at(0.0));
    retunes_ = trajectory_->retunes(o.pose_update_s);
  }
}

// --measure-out along a trajectory: every stop long enough for a stopped measurement's plan.
void PlantEmulator::check_measure_dwells() const {
  if (!o_.measure_out.empty() && trajectory_)
    check_measurement_stops(*trajectory_, analysis::commissioning_plan(cfg_, model_));
}

// The spindle (steps and ramps) and the cut at its speed: checked before any controller is served.
void PlantEmulator::setup_cut() {
  changes_ = o_.spindle_ramps;
  for (const auto& [t, rpm] : o_.spindle_schedule) changes_.push_back({t, t, rpm});
  std::optional<CutLoad> cut;
  if (!o_.cut_job.empty() && o_.cut_model == EmulatorOptions::CutModel::kRegenerative) {
    RegenerativeCutOptions ro = o_.regenerative;
    ro.job_path = o_.cut_job;
    ro.spindle = changes_, ro.depth = o_.depth_changes;
    ro.program_period_s = o_.spindle_register_period_s;
    changes_.clear();  // the cut's own program: the register shows the speed it turns at
    regenerative_.emplace(cfg_, plant_, ro);
    const RegenerativeCutReport head = regenerative_->report();
    spdlog::info(
        "robodamp plant: regenerative cut {}: {:.3f} mm at {:.1f} rpm ({} steps per tooth), {} revolutions{}{}",
        o_.cut_job, head.axial_mm, head.rpm, head.steps_per_tooth, head.revolutions,
        head.start_s >= 0.0 ? fmt::format(" from {:.3f} s", head.start_s)
                            : std::string(" once the loop is at full gain"),
        ro.spindle.empty() && ro.depth.empty() ? "" : " after the program's last change");
  } else if (!o_.cut_job.empty()) {
    cut = cut_load_from_job(o_.cut_job, model_, o_.cut_harmonics);
    spdlog::info("robodamp plant: cutting {} ({} teeth) at the {}: tooth harmonics {:.1f}, {:.1f}, {:.1f} N",
                 o_.cut_job, cut->teeth, model_.locations[cut->location].name, std::abs(cut->harmonics_n[1]),
                 std::abs(cut->harmonics_n[2]), std::abs(cut->harmonics_n[3]));
  }
  cutting_.emplace(plant_, std::move(cut), SpindleProfile(std::move(changes_)));
}

// The controller's connection (a UNIX socket the controller connects to, or a CAN interface), then the
// real-time set-up of this process when it paces in real time.
void PlantEmulator::connect() {
  if (can_.interface.rfind("unix:", 0) == 0) {
    listener_.emplace(can_.interface.substr(5));
    spdlog::info("robodamp plant: waiting for the controller on {} ({}), Modbus {}", can_.interface, rep_.pacing,
                 rep_.modbus);
    const int fd = listener_->accept(cfg_.hil.accept_timeout_s);
    if (fd < 0)
      throw std::runtime_error("no controller connected to " + can_.interface +
                               " within hil.accept_timeout_s = " + std::to_string(cfg_.hil.accept_timeout_s) + " s");
    channel_.emplace(drivers::CanChannel::adopt(fd));
  } else {
    channel_.emplace(
        drivers::CanChannel::open_interface(can_.interface, can_.fd, can_.command.id, can_.command.extended_id));
  }
  spdlog::info("robodamp plant: controller connected");
  if (pacing_ == config::HilPacing::kRealtime && o_.realtime_setup) {
    config::RealtimeConfig rc = cfg_.realtime;
    rc.priority = std::max(0, rc.priority - 1);  // below the loop's thread when both share a machine
    rc.cpu = -1;
    rt_process_.emplace(rc, rts_);
    rt::setup_realtime_thread(rc, rts_);
    for (const auto& w : rts_.warnings) spdlog::warn("robodamp plant: {}", w);
  }
}

// Allocated now: starting them later only schedules the hits (the realtime pacing never stalls for it).
void PlantEmulator::setup_campaigns() {
  if (!o_.measure_out.empty()) {
    const analysis::CommissioningPlan plan = analysis::commissioning_plan(cfg_, model_);
    if (!trajectory_) {
      modal_tests_.emplace_back(o_.measure_out, std::make_unique<analysis::ModalTest>(cfg_, plant_, plan));
      spdlog::info("robodamp plant: commissioning measurement: {} impacts at each location from {:.1f} s, FRFs to {}",
                   cfg_.commissioning.impacts_per_location, plan.impacts_start_s.front(), o_.measure_out);
    }
    std::size_t k = 0;
    for (const PoseDwell& d : trajectory_ ? trajectory_->stops() : std::vector<PoseDwell>{}) {
      analysis::CommissioningPlan at = plan;  // a stopped measurement's times from the robot's stop
      for (double& t : at.impacts_start_s) t += d.t0_s;
      const std::string dir = o_.measure_out + "/dwell_" + std::to_string(++k);
      modal_tests_.emplace_back(dir, std::make_unique<analysis::ModalTest>(cfg_, plant_, at));
      spdlog::info(
          "robodamp plant: commissioning measurement at dwell {} ({}): {} impacts at each location from {:.1f} s, "
          "FRFs to {}",
          k, config::describe_pose(d.joints_deg), cfg_.commissioning.impacts_per_location, at.impacts_start_s.front(),
          dir);
    }
    for (const auto& [dir, test] : modal_tests_) rep_.measure_records_planned += test->records_planned();
  } else if (o_.impacts && !trajectory_) {
    campaign_.emplace(cfg_, plant_, test_);
  }
  if (trajectory_ && o_.impacts && o_.measure_out.empty()) {
    dwell_campaigns_.emplace(cfg_, plant_, *trajectory_, test_);
    rep_.records_planned = 0;
    spdlog::info("robodamp plant: the robot moves along {} waypoints; impacts at {} dwells", o_.pose_trajectory.size(),
                 dwell_campaigns_->count());
  }
}

void PlantEmulator::run() {
  setup_campaigns();
  wall0_ = Clock::now();
  if (o_.max_duration_s > 0.0) max_ticks_ = static_cast<std::uint64_t>(std::llround(o_.max_duration_s * fs_));
  send_sensor();  // tick 0's sample
  rep_.end_reason = "the controller disconnected";
  if (pacing_ == config::HilPacing::kLockstep)
    run_lockstep();
  else
    run_realtime();
  if (rep_.ticks >= max_ticks_) rep_.end_reason = "--duration reached";
}

// One plant period per command: command k answers sensor frame k; the plant steps with command k-1.
void PlantEmulator::run_lockstep() {
  bool got = false;
  while (rep_.ticks < max_ticks_) {
    if (stopping()) {
      rep_.end_reason = "signal";
      return;
    }
    if (!receive_commands(got)) return;
    if (!got) {
      if (!channel_->wait_readable(static_cast<std::int64_t>(kSilentControllerS * 1e9))) {
        rep_.end_reason = "the controller went silent (no command frame for 10 s)";
        return;
      }
      continue;
    }
    step_plant();
    applied_v_ = command_v_;
    send_sensor();
  }
}

// One plant period per period of the wall clock (rt::DeadlinePacer, as the loop's): behind, the plant
// skips ahead and holds its pace in steps, not in a burst; a period without a command holds the last.
void PlantEmulator::run_realtime() {
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / fs_));
  rt::DeadlinePacer pacer(period_ns, rt::monotonic_ns());
  bool got = false;
  while (rep_.ticks < max_ticks_) {
    if (stopping()) {
      rep_.end_reason = "signal";
      return;
    }
    pacer.advance();
    const rt::DeadlinePacer::Wake w = pacer.wait();
    rep_.wake_latency.record(w.late_ns);
    if (w.missed > 0) ++rep_.overruns;
    if (!receive_commands(got)) return;
    if (!got) ++rep_.held_periods;
    applied_v_ = command_v_;
    step_plant();
    send_sensor();
  }
}

void PlantEmulator::inject(const char* kind, double t) {
  rep_.injected.push_back({kind, t, rt::monotonic_ns()});
  spdlog::warn("robodamp plant: injected {} at {:.3f} s", kind, t);
}

void PlantEmulator::send_error_frame(canid_t flags) {
  canfd_frame e{};
  e.can_id = CAN_ERR_FLAG | flags;
  e.len = CAN_ERR_DLC;
  (void)channel_->send(e, static_cast<int>(CAN_MTU));
}

void PlantEmulator::faults_at(double t) {
  if (!bus_off_done_ && o_.bus_off_at_s >= 0.0 && t >= o_.bus_off_at_s) {
    bus_off_done_ = true;
    bus_off_until_s_ = t + o_.bus_off_for_s;
    send_error_frame(CAN_ERR_BUSOFF);
    inject("bus_off", t);
  }
  if (bus_off_until_s_ >= 0.0 && t >= bus_off_until_s_) {
    bus_off_until_s_ = -1.0;
    send_error_frame(CAN_ERR_RESTARTED);
    inject("bus_restarted", t);
  }
  if (!hang_done_ && o_.modbus_hang_at_s >= 0.0 && t >= o_.modbus_hang_at_s) {
    hang_done_ = true;
    regs_.hang();
    inject("modbus_hang", t);
  }
}

void PlantEmulator::send_sensor() {
  faults_at(static_cast<double>(rep_.ticks) * dt_);
  if (bus_off_until_s_ >= 0.0) {  // off the bus: the DAQ's frames do not arrive (the plant goes on)
    (void)plant_.sense();
    return;
  }
  const sim::SensorReading s = plant_.sense();
  if (regenerative_) regenerative_->sensed(s.accel_mps2, static_cast<double>(rep_.ticks) * dt_);
  const drivers::Encoded e = drivers::encode(can_.sensor, can_.fd, s.accel_mps2, sensor_counter_++);
  if (channel_->send(e.frame, e.frame_bytes) == 0)
    ++rep_.sensor_frames_sent;
  else
    ++rep_.send_errors;
}

bool PlantEmulator::receive_commands(bool& got) {
  got = false;
  for (;;) {
    canfd_frame f{};
    std::int64_t ts = 0;
    const int n = channel_->receive(f, ts);
    if (n == 0) return true;
    if (n < 0) return false;
    const drivers::Decoded d = drivers::decode(can_.command, f, n);
    if (d.error == drivers::DecodeError::kWrongId) {
      ++rep_.frames_other;
      continue;
    }
    if (d.error != drivers::DecodeError::kNone) {
      ++rep_.frames_malformed;
      continue;
    }
    if (can_.command.counter) {
      if (have_cmd_counter_)
        rep_.commands_lost +=
            drivers::counter_step(last_cmd_counter_, d.counter, drivers::counter_mask(*can_.command.counter)).lost;
      last_cmd_counter_ = d.counter, have_cmd_counter_ = true;
    }
    ++rep_.command_frames;
    command_v_ = d.value;
    got = true;
  }
}

// The robot reads robodamp's advice block and, with spindle.apply_advice, turns the spindle to the
// advised speed (a speed outside 0 < rpm <= spindle.rpm_max is refused, as a robot controller would).
void PlantEmulator::read_advice(double t) {
  const auto a = regs_.advice();
  if (!a || (*a)[0] == advice_seq_ || ((*a)[0] == 0 && (*a)[3] == 0)) return;  // none, or no new one
  advice_seq_ = (*a)[0];
  const drivers::modbus_codec::Advice d = drivers::modbus_codec::decode_advice(*a, regs_.rpm_per_count());
  AdviceSeen seen{t, advice_seq_, static_cast<int>(d.status), d.rpm, d.margin, {}};
  if (seen.status == 2)
    seen.action = "kept the speed: no stable speed";
  else if (seen.status == 3)
    seen.action = "kept the speed: withdrawn (the state it was for is gone)";
  else if (seen.status != 1)
    seen.action = "refused: status " + std::to_string(seen.status) + " (allowed 1, 2 or 3)";
  else if (!(seen.rpm > 0.0) || seen.rpm > cfg_.spindle.rpm_max)
    seen.action = fmt::format("refused: {} rpm outside the spindle's 0 < rpm <= {} rpm (spindle.rpm_max)", seen.rpm,
                              cfg_.spindle.rpm_max);
  else if (!cfg_.spindle.apply_advice)
    seen.action = "not followed (spindle.apply_advice false)";
  else if (regenerative_->ended())
    seen.action = "not followed: the cut has ended";
  else
    seen.action = "followed", regenerative_->follow_advice(seen.rpm, t);
  regenerative_->advice_read(t);
  spdlog::info("robodamp plant: advice #{} at {:.3f} s: status {}, {:.1f} rpm, margin {:.2f}: {}", seen.seq, t,
               seen.status, seen.rpm, seen.margin, seen.action);
  rep_.advice.push_back(std::move(seen));
}

// The robot moves: its registers, then the plant's modes at the pose now.
void PlantEmulator::move_robot(double t) {
  if (!trajectory_) return;
  if (t >= pose_published_s_ + o_.pose_register_period_s) regs_.set_joints(trajectory_->at(t)), pose_published_s_ = t;
  for (; next_retune_ < retunes_.size() && retunes_[next_retune_].first <= t; ++next_retune_) {
    plant_.retune(std::move(retunes_[next_retune_].second));
    ++rep_.pose_retunes;
  }
}

// The robot controller updates its spindle register every spindle_register_period_s (a ramp arrives as
// a staircase the controller's settle rule can follow); the cut sees the speed itself.
double PlantEmulator::turn_spindle(double t) {
  double rpm = cutting_->before_step(t);
  if (regenerative_) {
    if (t >= advice_polled_s_ + kAdvicePollS) advice_polled_s_ = t, read_advice(t);
    regenerative_->before_step(t);
    rpm = regenerative_->rpm();
    const double depth_mm = regenerative_->active() ? regenerative_->axial_mm() : 0.0;  // 0: not in the cut
    if (depth_mm != published_depth_mm_) regs_.set_depth_mm(published_depth_mm_ = depth_mm);
  }
  if (rpm != published_rpm_ && t >= published_at_s_ + o_.spindle_register_period_s) {
    regs_.set_spindle_rpm(rpm);
    published_rpm_ = rpm, published_at_s_ = t;
  }
  return rpm;
}

void PlantEmulator::step_plant() {
  const std::size_t k = rep_.ticks;
  const double t = static_cast<double>(k) * dt_;
  if (campaign_) campaign_->before_step(k);
  if (dwell_campaigns_) dwell_campaigns_->before_step(k);
  for (auto& [dir, test] : modal_tests_) test->before_step(k);
  move_robot(t);
  (void)turn_spindle(t);
  plant_.step(ready_ ? applied_v_ : 0.0);
  after_step(k, t);
  ++rep_.ticks;
  amplifier(k, t);
  robot_reports(t);
}

void PlantEmulator::after_step(std::size_t k, double t) {
  if (regenerative_) {
    regenerative_->after_step();
    if (regenerative_->ended() && !cut_end_logged_)
      cut_end_logged_ = true, spdlog::info("robodamp plant: the regenerative cut ended at {:.3f} s", t + dt_);
  }
  cutting_->after_step(ready_ ? applied_v_ : 0.0, dt_);
  if (dwell_campaigns_) dwell_campaigns_->after_step(k);
  for (auto& [dir, test] : modal_tests_) test->after_step(k);
  if (campaign_) {
    campaign_->after_step(k);
    if (campaign_->done(k + 1) && !rep_.campaign_complete) {
      rep_.campaign_complete = true;
      spdlog::info("robodamp plant: impact schedule complete at {:.1f} s ({} records)", t, campaign_->records());
    }
  }
}

// The amplifier: the enable coil, ready after the delay, heating with the mean-square drive; the
// impact schedule starts settle_s after it is first ready.
void PlantEmulator::amplifier(std::size_t k, double t) {
  const bool en = regs_.enable();
  if (en != enabled_) {
    enabled_ = en, enabled_at_s_ = t, ++rep_.enable_changes;
    spdlog::info("robodamp plant: amplifier {} at {:.3f} s", en ? "enabled" : "disabled", t);
  }
  const bool now_ready = enabled_ && t - enabled_at_s_ >= cfg_.hil.amplifier_ready_delay_s;
  if (now_ready != ready_) regs_.set_ready(now_ready), ready_ = now_ready;
  if (ready_ && regenerative_) regenerative_->amplifier_ready(t);
  if (enabled_) rep_.enabled_s += dt_;
  const double v = ready_ ? applied_v_ : 0.0;
  rep_.peak_command_v = std::max(rep_.peak_command_v, std::abs(v));
  ms_v_ += (v * v - ms_v_) * dt_ / kTemperatureTauS;
  if (k % 100 == 0) {
    temperature_c_ = cfg_.hil.ambient_c + cfg_.hil.heating_c_per_v2 * ms_v_;
    rep_.peak_temperature_c = std::max(rep_.peak_temperature_c, temperature_c_);
    regs_.set_temperature(temperature_c_);
  }
  if (campaign_ && !campaign_->started() && ready_) {
    rep_.campaign_started = true;
    rep_.campaign_start_s = t + cfg_.hil.settle_s;
    campaign_->start(rep_.campaign_start_s);
    spdlog::info("robodamp plant: amplifier ready at {:.3f} s; {} impacts at the {} from {:.1f} s", t,
                 cfg_.bench.averages, rep_.impact_location, rep_.campaign_start_s);
  }
}

// The robot's scheduled reports: the spindle speed (logged) and the mounting register.
void PlantEmulator::robot_reports(double t) {
  while (next_spindle_ < o_.spindle_schedule.size() && o_.spindle_schedule[next_spindle_].first <= t) {
    ++rep_.spindle_changes;
    spdlog::info("robodamp plant: robot reports the spindle at {} rpm at {:.3f} s",
                 o_.spindle_schedule[next_spindle_].second, t);
    ++next_spindle_;
  }
  while (next_mounting_ < o_.mounting_schedule.size() && o_.mounting_schedule[next_mounting_].first <= t) {
    regs_.set_mounting(o_.mounting_schedule[next_mounting_].second);
    ++rep_.mounting_changes;
    spdlog::info("robodamp plant: robot reports {} mounting at {:.3f} s",
                 config::to_string(o_.mounting_schedule[next_mounting_].second), t);
    ++next_mounting_;
  }
}

}  // namespace detail

EmulatorReport run_emulator(const config::Config& configured, const EmulatorOptions& o) {
  // hil.robot_model: the robot the emulator moves is not the model the controller is configured with.
  config::Config cfg = configured;
  if (cfg.pose_schedule && !cfg.hil.robot_model_resolved.empty()) {
    cfg.pose_schedule->model_resolved = cfg.hil.robot_model_resolved;
    spdlog::info("robodamp plant: the robot moved is {} (hil.robot_model), not the controller's {}",
                 cfg.hil.robot_model_resolved, configured.pose_schedule->model_resolved);
  }
  detail::PlantEmulator emulator(cfg, o);
  emulator.connect();
  emulator.run();
  return emulator.finish();
}

}  // namespace robodamp::hil
