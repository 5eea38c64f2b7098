#include "hil/plant_emulator.hpp"

#include <linux/can/error.h>

#include <time.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "analysis/bench_run.hpp"
#include "drivers/can_channel.hpp"
#include "drivers/can_codec.hpp"
#include "hil/emulator_registers.hpp"
#include "rt/realtime.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::hil {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kSilentControllerS = 10.0;  // lockstep: no command for this long ends the run
constexpr double kTemperatureTauS = 10.0;    // amplifier heating time constant
constexpr double kAdvicePollS = 0.01;        // how often the robot program reads the advice block (plant time)

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

sim::Plant make_plant(const config::Config& cfg, const sim::PlantModel& model) {
  sim::Plant plant(model, cfg);
  if (cfg.disturbances.drives_on) plant.add_excitation(sim::make_drive_vibration(model, cfg));
  return plant;
}

}  // namespace

EmulatorReport run_emulator(const config::Config& cfg, const EmulatorOptions& o) {
  if (!cfg.can || !cfg.modbus)
    throw config::ConfigError({{cfg.source, {}, cfg.can ? "modbus" : "can",
                                cfg.can ? "missing: the emulator serves the amplifier's registers from the modbus section"
                                        : "missing: the emulator sends and receives the frames of the can section"}});
  const config::CanConfig& can = *cfg.can;
  EmulatorReport rep;
  rep.config = cfg.source;
  const config::HilPacing pacing = o.pacing.value_or(cfg.hil.pacing);
  rep.pacing = config::to_string(pacing);
  rep.transport = can.interface;
  const double fs = cfg.loop.rate_hz, dt = 1.0 / fs;

  std::optional<PoseTrajectory> trajectory;
  if (!o.pose_trajectory.empty()) trajectory.emplace(cfg, o.pose_trajectory);
  const sim::PlantModel model = trajectory ? trajectory->plant_at(trajectory->at(0.0)) : sim::build_plant_model(cfg);
  sim::Plant plant = make_plant(cfg, model);
  const int impact_id = o.impact_location > 0 ? o.impact_location
                                              : (cfg.robot.frfs.empty() ? 1 : cfg.robot.frfs.front().excitation_location);
  const std::size_t impact_index = model.index_of(impact_id);
  rep.impact_location = model.locations[impact_index].name + " (location " + std::to_string(impact_id) + ")";
  const analysis::ImpactTest test{impact_index, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, true,
                                  cfg.controller.gain_ns_per_m, cfg.controller.polarity};
  rep.records_planned = o.impacts && o.measure_out.empty() ? cfg.bench.averages : 0;
  // The spindle (steps and ramps) and the cut at its speed: checked before any controller is served.
  std::vector<SpindleChange> changes = o.spindle_ramps;
  for (const auto& [t, rpm] : o.spindle_schedule) changes.push_back({t, t, rpm});
  std::optional<CutLoad> cut;
  std::optional<RegenerativeCut> regenerative;
  const bool regenerative_model = o.cut_model == EmulatorOptions::CutModel::kRegenerative;
  if (!o.cut_job.empty() && regenerative_model) {
    RegenerativeCutOptions ro = o.regenerative;
    ro.job_path = o.cut_job;
    ro.spindle = changes, ro.depth = o.depth_changes;
    ro.program_period_s = o.spindle_register_period_s;
    changes.clear();  // the cut's own program: the register shows the speed it turns at
    regenerative.emplace(cfg, plant, ro);
    const RegenerativeCutReport head = regenerative->report();
    spdlog::info("robodamp plant: regenerative cut {}: {:.3f} mm at {:.1f} rpm ({} steps per tooth), {} revolutions{}{}",
                 o.cut_job, head.axial_mm, head.rpm, head.steps_per_tooth, head.revolutions,
                 head.start_s >= 0.0 ? fmt::format(" from {:.3f} s", head.start_s) : std::string(" once the loop is at full gain"),
                 ro.spindle.empty() && ro.depth.empty() ? "" : " after the program's last change");
  } else if (!o.cut_job.empty()) {
    cut = cut_load_from_job(o.cut_job, model, o.cut_harmonics);
    spdlog::info("robodamp plant: cutting {} ({} teeth) at the {}: tooth harmonics {:.1f}, {:.1f}, {:.1f} N", o.cut_job,
                 cut->teeth, model.locations[cut->location].name, std::abs(cut->harmonics_n[1]),
                 std::abs(cut->harmonics_n[2]), std::abs(cut->harmonics_n[3]));
  }
  CuttingLoad cutting(plant, std::move(cut), SpindleProfile(std::move(changes)));

  EmulatorRegisters regs(cfg);
  rep.modbus = regs.describe();
  regs.set_temperature(cfg.hil.ambient_c);
  double pose_published_s = 0.0;
  std::vector<std::pair<double, sim::PlantModel>> retunes;  // the structure along the trajectory, built now
  std::size_t next_retune = 0;
  if (trajectory) {
    regs.set_joints(trajectory->at(0.0));
    retunes = trajectory->retunes(o.pose_update_s);
  }

  // The controller's connection.
  std::optional<drivers::CanListener> listener;
  std::optional<drivers::CanChannel> channel;
  if (can.interface.rfind("unix:", 0) == 0) {
    listener.emplace(can.interface.substr(5));
    spdlog::info("robodamp plant: waiting for the controller on {} ({}), Modbus {}", can.interface, rep.pacing, rep.modbus);
    const int fd = listener->accept(cfg.hil.accept_timeout_s);
    if (fd < 0) throw std::runtime_error("no controller connected to " + can.interface + " within hil.accept_timeout_s = " +
                                         std::to_string(cfg.hil.accept_timeout_s) + " s");
    channel.emplace(drivers::CanChannel::adopt(fd));
  } else {
    channel.emplace(drivers::CanChannel::open_interface(can.interface, can.fd, can.command.id, can.command.extended_id));
  }
  spdlog::info("robodamp plant: controller connected");

  rt::RealtimeStatus rts;
  std::optional<rt::RealtimeProcess> rt_process;
  if (pacing == config::HilPacing::kRealtime && o.realtime_setup) {
    config::RealtimeConfig rc = cfg.realtime;
    rc.priority = std::max(0, rc.priority - 1);  // below the loop's thread when both share a machine
    rc.cpu = -1;
    rt_process.emplace(rc, rts);
    rt::setup_realtime_thread(rc, rts);
    for (const auto& w : rts.warnings) spdlog::warn("robodamp plant: {}", w);
  }

  // Allocated now: starting it later only schedules the hits (the realtime pacing never stalls for it).
  std::optional<analysis::ImpactCampaign> campaign;
  std::unique_ptr<analysis::ModalTest> modal_test;
  if (!o.measure_out.empty()) {
    modal_test = std::make_unique<analysis::ModalTest>(cfg, plant, analysis::commissioning_plan(cfg, model));
    rep.measure_records_planned = modal_test->records_planned();
    spdlog::info("robodamp plant: commissioning measurement: {} impacts at each location from {:.1f} s, FRFs to {}",
                 cfg.commissioning.impacts_per_location, analysis::commissioning_plan(cfg, model).impacts_start_s.front(),
                 o.measure_out);
  } else if (o.impacts && !trajectory) {
    campaign.emplace(cfg, plant, test);
  }
  std::optional<DwellCampaigns> dwell_campaigns;
  if (trajectory && o.impacts) {
    dwell_campaigns.emplace(cfg, plant, *trajectory, test);
    rep.records_planned = 0;
    spdlog::info("robodamp plant: the robot moves along {} waypoints; impacts at {} dwells", o.pose_trajectory.size(),
                 dwell_campaigns->count());
  }
  double published_rpm = -1.0, published_at_s = -1.0;
  std::uint32_t sensor_counter = 0, last_cmd_counter = 0;
  bool have_cmd_counter = false;
  double command_v = 0.0;     // newest command received
  double applied_v = 0.0;     // what the amplifier drives this period with
  bool enabled = false, ready = false;
  double enabled_at_s = 0.0, ms_v = 0.0, temperature_c = cfg.hil.ambient_c;
  std::size_t next_mounting = 0, next_spindle = 0;
  const auto wall0 = Clock::now();
  std::int64_t deadline = now_ns();
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / fs));
  const auto max_ticks = o.max_duration_s > 0.0 ? static_cast<std::uint64_t>(std::llround(o.max_duration_s * fs)) : UINT64_MAX;

  // Fault injection (plant time): the bus off for a while, the Modbus device hanging.
  double bus_off_until_s = -1.0;
  bool bus_off_done = false, hang_done = false;
  auto inject = [&](const char* kind, double t) {
    rep.injected.push_back({kind, t, now_ns()});
    spdlog::warn("robodamp plant: injected {} at {:.3f} s", kind, t);
  };
  auto send_error_frame = [&](canid_t flags) {
    canfd_frame e{};
    e.can_id = CAN_ERR_FLAG | flags;
    e.len = CAN_ERR_DLC;
    (void)channel->send(e, static_cast<int>(CAN_MTU));
  };
  auto faults_at = [&](double t) {
    if (!bus_off_done && o.bus_off_at_s >= 0.0 && t >= o.bus_off_at_s) {
      bus_off_done = true;
      bus_off_until_s = t + o.bus_off_for_s;
      send_error_frame(CAN_ERR_BUSOFF);
      inject("bus_off", t);
    }
    if (bus_off_until_s >= 0.0 && t >= bus_off_until_s) {
      bus_off_until_s = -1.0;
      send_error_frame(CAN_ERR_RESTARTED);
      inject("bus_restarted", t);
    }
    if (!hang_done && o.modbus_hang_at_s >= 0.0 && t >= o.modbus_hang_at_s) {
      hang_done = true;
      regs.hang();
      inject("modbus_hang", t);
    }
  };
  auto send_sensor = [&]() {
    faults_at(static_cast<double>(rep.ticks) * dt);
    if (bus_off_until_s >= 0.0) {  // off the bus: the DAQ's frames do not arrive (the plant goes on)
      (void)plant.sense();
      return;
    }
    const sim::SensorReading s = plant.sense();
    if (regenerative) regenerative->sensed(s.accel_mps2, static_cast<double>(rep.ticks) * dt);
    const drivers::Encoded e = drivers::encode(can.sensor, can.fd, s.accel_mps2, sensor_counter++);
    if (channel->send(e.frame, e.frame_bytes) == 0) ++rep.sensor_frames_sent;
    else ++rep.send_errors;
  };
  // Drains the frames waiting; false when the controller has gone.
  auto receive_commands = [&](bool& got) {
    got = false;
    for (;;) {
      canfd_frame f{};
      std::int64_t ts = 0;
      const int n = channel->receive(f, ts);
      if (n == 0) return true;
      if (n < 0) return false;
      const drivers::Decoded d = drivers::decode(can.command, f, n);
      if (d.error == drivers::DecodeError::kWrongId) {
        ++rep.frames_other;
        continue;
      }
      if (d.error != drivers::DecodeError::kNone) {
        ++rep.frames_malformed;
        continue;
      }
      if (can.command.counter) {
        if (have_cmd_counter)
          rep.commands_lost += drivers::counter_step(last_cmd_counter, d.counter, drivers::counter_mask(*can.command.counter)).lost;
        last_cmd_counter = d.counter, have_cmd_counter = true;
      }
      ++rep.command_frames;
      command_v = d.value;
      got = true;
    }
  };
  // The robot reads robodamp's advice block and, with spindle.apply_advice, turns the spindle to the
  // advised speed (a speed outside 0 < rpm <= spindle.rpm_max is refused, as a robot controller would).
  double published_depth_mm = -1.0, advice_polled_s = -1.0;
  bool cut_end_logged = false;
  unsigned advice_seq = 0;
  auto read_advice = [&](double t) {
    const auto a = regs.advice();
    if (!a || (*a)[0] == advice_seq || ((*a)[0] == 0 && (*a)[3] == 0)) return;  // none, or no new one
    advice_seq = (*a)[0];
    AdviceSeen seen{t, advice_seq, (*a)[3], (*a)[1] * regs.rpm_per_count(), (*a)[2] / 100.0, {}};
    if (seen.status == 2) seen.action = "kept the speed: no stable speed";
    else if (seen.status != 1) seen.action = "refused: status " + std::to_string(seen.status) + " (allowed 1 or 2)";
    else if (!(seen.rpm > 0.0) || seen.rpm > cfg.spindle.rpm_max)
      seen.action = fmt::format("refused: {} rpm outside the spindle's 0 < rpm <= {} rpm (spindle.rpm_max)", seen.rpm,
                                cfg.spindle.rpm_max);
    else if (!cfg.spindle.apply_advice) seen.action = "not followed (spindle.apply_advice false)";
    else if (regenerative->ended()) seen.action = "not followed: the cut has ended";
    else seen.action = "followed", regenerative->follow_advice(seen.rpm, t);
    regenerative->advice_read(t);
    spdlog::info("robodamp plant: advice #{} at {:.3f} s: status {}, {:.1f} rpm, margin {:.2f}: {}", seen.seq, t, seen.status,
                 seen.rpm, seen.margin, seen.action);
    rep.advice.push_back(std::move(seen));
  };
  // One plant period with the amplifier's output, then the amplifier and robot registers.
  auto step_plant = [&]() {
    const std::size_t k = rep.ticks;
    const double t = static_cast<double>(k) * dt;
    if (campaign) campaign->before_step(k);
    if (dwell_campaigns) dwell_campaigns->before_step(k);
    if (modal_test) modal_test->before_step(k);
    if (trajectory) {  // the robot moves: its registers, then the plant's modes at the pose now
      if (t >= pose_published_s + o.pose_register_period_s) regs.set_joints(trajectory->at(t)), pose_published_s = t;
      for (; next_retune < retunes.size() && retunes[next_retune].first <= t; ++next_retune) {
        plant.retune(std::move(retunes[next_retune].second));
        ++rep.pose_retunes;
      }
    }
    // The robot controller updates its spindle register every spindle_register_period_s (a ramp arrives
    // as a staircase the controller's settle rule can follow); the cut sees the speed itself.
    double rpm = cutting.before_step(t);
    if (regenerative) {
      if (t >= advice_polled_s + kAdvicePollS) advice_polled_s = t, read_advice(t);
      regenerative->before_step(t);
      rpm = regenerative->rpm();
      const double depth_mm = regenerative->active() ? regenerative->axial_mm() : 0.0;  // 0: not in the cut
      if (depth_mm != published_depth_mm) regs.set_depth_mm(published_depth_mm = depth_mm);
    }
    if (rpm != published_rpm && t >= published_at_s + o.spindle_register_period_s) {
      regs.set_spindle_rpm(rpm);
      published_rpm = rpm, published_at_s = t;
    }
    plant.step(ready ? applied_v : 0.0);
    if (regenerative) {
      regenerative->after_step();
      if (regenerative->ended() && !cut_end_logged)
        cut_end_logged = true, spdlog::info("robodamp plant: the regenerative cut ended at {:.3f} s", t + dt);
    }
    cutting.after_step(ready ? applied_v : 0.0, dt);
    if (dwell_campaigns) dwell_campaigns->after_step(k);
    if (modal_test) modal_test->after_step(k);
    if (campaign) {
      campaign->after_step(k);
      if (campaign->done(k + 1) && !rep.campaign_complete) {
        rep.campaign_complete = true;
        spdlog::info("robodamp plant: impact schedule complete at {:.1f} s ({} records)", t, campaign->records());
      }
    }
    ++rep.ticks;
    // Amplifier: the enable coil, ready after the delay; heating with the mean-square drive.
    const bool en = regs.enable();
    if (en != enabled) {
      enabled = en, enabled_at_s = t, ++rep.enable_changes;
      spdlog::info("robodamp plant: amplifier {} at {:.3f} s", en ? "enabled" : "disabled", t);
    }
    const bool now_ready = enabled && t - enabled_at_s >= cfg.hil.amplifier_ready_delay_s;
    if (now_ready != ready) regs.set_ready(now_ready), ready = now_ready;
    if (ready && regenerative) regenerative->amplifier_ready(t);
    if (enabled) rep.enabled_s += dt;
    const double v = ready ? applied_v : 0.0;
    rep.peak_command_v = std::max(rep.peak_command_v, std::abs(v));
    ms_v += (v * v - ms_v) * dt / kTemperatureTauS;
    if (k % 100 == 0) {
      temperature_c = cfg.hil.ambient_c + cfg.hil.heating_c_per_v2 * ms_v;
      rep.peak_temperature_c = std::max(rep.peak_temperature_c, temperature_c);
      regs.set_temperature(temperature_c);
    }
    // The impact schedule starts settle_s after the amplifier is first ready.
    if (campaign && !campaign->started() && ready) {
      rep.campaign_started = true;
      rep.campaign_start_s = t + cfg.hil.settle_s;
      campaign->start(rep.campaign_start_s);
      spdlog::info("robodamp plant: amplifier ready at {:.3f} s; {} impacts at the {} from {:.1f} s", t,
                   cfg.bench.averages, rep.impact_location, rep.campaign_start_s);
    }
    while (next_spindle < o.spindle_schedule.size() && o.spindle_schedule[next_spindle].first <= t) {
      ++rep.spindle_changes;
      spdlog::info("robodamp plant: robot reports the spindle at {} rpm at {:.3f} s", o.spindle_schedule[next_spindle].second, t);
      ++next_spindle;
    }
    while (next_mounting < o.mounting_schedule.size() && o.mounting_schedule[next_mounting].first <= t) {
      regs.set_mounting(o.mounting_schedule[next_mounting].second);
      ++rep.mounting_changes;
      spdlog::info("robodamp plant: robot reports {} mounting at {:.3f} s",
                   config::to_string(o.mounting_schedule[next_mounting].second), t);
      ++next_mounting;
    }
  };
  auto stopping = [&]() { return o.stop_flag != nullptr && o.stop_flag->load() != 0; };

  send_sensor();  // tick 0's sample
  bool got = false;
  if (pacing == config::HilPacing::kLockstep) {
    rep.end_reason = "the controller disconnected";
    while (rep.ticks < max_ticks) {
      if (stopping()) {
        rep.end_reason = "signal";
        break;
      }
      // Command k (the reply to sensor frame k).
      if (!receive_commands(got)) break;
      if (!got) {
        if (!channel->wait_readable(static_cast<std::int64_t>(kSilentControllerS * 1e9))) {
          rep.end_reason = "the controller went silent (no command frame for 10 s)";
          break;
        }
        continue;
      }
      step_plant();  // with command k-1
      applied_v = command_v;
      send_sensor();
    }
  } else {
    rep.end_reason = "the controller disconnected";
    while (rep.ticks < max_ticks) {
      if (stopping()) {
        rep.end_reason = "signal";
        break;
      }
      deadline += period_ns;
      const timespec ts{static_cast<time_t>(deadline / 1'000'000'000), static_cast<long>(deadline % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
      const std::int64_t late = now_ns() - deadline;
      rep.wake_latency.record(late);
      if (late > period_ns) {  // behind: skip ahead (the plant holds its pace in steps, not in a burst)
        ++rep.overruns;
        deadline += (late / period_ns) * period_ns;
      }
      if (!receive_commands(got)) break;
      if (!got) ++rep.held_periods;
      applied_v = command_v;
      step_plant();
      send_sensor();
    }
  }
  if (rep.ticks >= max_ticks) rep.end_reason = "--duration reached";
  rep.plant_time_s = static_cast<double>(rep.ticks) * dt;
  rep.elapsed_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  rep.modbus_requests = regs.requests();
  rep.cutting = cutting.report();
  if (regenerative) rep.regenerative_cut = regenerative->report();

  if (dwell_campaigns) rep.pose_dwells = dwell_campaigns->finish();
  if (modal_test) {
    rep.measure_records = modal_test->records();
    rep.measure_files = modal_test->write_frf_csvs(o.measure_out);
    spdlog::info("robodamp plant: {} of {} impact records; wrote {} FRFs to {}", rep.measure_records,
                 rep.measure_records_planned, rep.measure_files.size(), o.measure_out);
  }
  if (campaign && campaign->started()) {
    rep.records = campaign->records();
    rep.closed_receptance = campaign->receptance();
    // The same schedule with the amplifier off: the open-loop reference, in process.
    sim::Plant open = make_plant(cfg, model);
    analysis::ImpactCampaign ref(cfg, open, test);
    ref.start(rep.campaign_start_s);
    for (std::size_t k = 0; k < ref.end_tick(); ++k) {
      ref.before_step(k);
      (void)open.sense();  // the control sensor's noise stream advances as in the closed-loop run
      open.step(0.0);
      ref.after_step(k);
    }
    rep.open_receptance = ref.receptance();
    if (rep.records > 0) {
      const double lo = cfg.analysis.band_min_hz, hi = cfg.analysis.band_max_hz;
      for (const auto& f : cfg.robot.frfs) {
        if (f.excitation_location != impact_id) continue;
        const std::size_t resp = model.index_of(f.response_location);
        const auto op = analysis::measured_peak(rep.open_receptance[resp], lo, hi);
        const auto cl = analysis::measured_peak(rep.closed_receptance[resp], lo, hi);
        rep.frfs.push_back({f.name, op.magnitude_m_per_n, op.freq_hz, cl.magnitude_m_per_n, cl.freq_hz,
                            (op.magnitude_m_per_n / cl.magnitude_m_per_n - 1.0) * 100.0,
                            std::min(op.coherence_min, cl.coherence_min)});
      }
    }
  }
  return rep;
}

}  // namespace robodamp::hil
