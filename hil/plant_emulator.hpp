// The hardware-in-the-loop plant emulator (robodamp plant): the simulated plant in a process of its own,
// behind the same wires a robot cell has. It is the DAQ node and the amplifier on the CAN transport
// (sensor frames out, command frames in, the configuration's can mapping), and the amplifier and robot
// controller on Modbus TCP (enable coil, ready / fault inputs, temperature register, mounting register).
//
// Pacing:
// - realtime: one plant step per loop period on CLOCK_MONOTONIC (clock_nanosleep, absolute deadlines).
//   Each period it takes the newest command frame that arrived, steps the plant with the amplifier's
//   output, and sends the sensor frame: true HIL timing, the controller's phase relative to it is
//   whatever the two clocks give.
// - lockstep: one plant step per command frame, as fast as the controller answers (the controller runs
//   on its virtual clock and waits for each sensor frame). Tick k: sensor frame k out, command k in, the
//   plant steps with command k-1, which is the one-period computation delay of the in-process bench, so
//   the same schedule measures the same loop through the real frame path.
//
// The amplifier drives the actuator only while its enable coil is set and after amplifier_ready_delay_s
// (plant time); its temperature rises with the mean-square command. Once it is ready, after hil.settle_s,
// the emulator runs the bench's impact schedule (bench.averages hits at the impact location) with
// measurement accelerometers on the plant side, and at the end runs the same schedule with the amplifier
// off in process for the open-loop reference: the FRFs it reports are measured, not modelled.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/modal_test.hpp"
#include "analysis/spectral.hpp"
#include "hil/cutting_load.hpp"
#include "hil/pose_trajectory.hpp"
#include "hil/regenerative_cut.hpp"
#include "config/config.hpp"
#include "rt/timing_histogram.hpp"

namespace robodamp::hil {

struct EmulatorOptions {
  std::optional<config::HilPacing> pacing;  // default hil.pacing
  double max_duration_s{0.0};               // plant time; 0 = until the controller disconnects
  bool impacts{true};
  int impact_location{0};
  // robodamp measure's plant side (analysis/modal_test.hpp): instead of the bench's impact schedule, the
  // commissioning plan's impacts at every location (plant time from the first step), and the FRFs
  // written to this directory when the run ends. With a pose trajectory, the plan at each of its stops
  // (from the stop's start) into measure_out/dwell_<k> (measure --along-path); a stop shorter than the plan
  // is refused. Empty = off.
  std::string measure_out;  // location id; 0 = the first configured FRF's excitation
  // Robot mounting register changes: (plant time s, mounting).
  std::vector<std::pair<double, config::Mounting>> mounting_schedule;
  // Spindle speed register changes: (plant time s, rpm), written to modbus.robot.spindle_rpm_register
  // (rpm / rpm_per_count).
  std::vector<std::pair<double, double>> spindle_schedule;
  // Linear spindle ramps (t0 s, t1 s, rpm reached at t1), with the steps above one speed profile.
  std::vector<SpindleChange> spindle_ramps;
  // How often the robot controller updates its spindle register (plant time; a ramp arrives as a
  // staircase). In lockstep, plant time outruns the controller's wall-clock Modbus poll, so a lockstep
  // ramp needs steps long enough for the poll's settle rule.
  double spindle_register_period_s{0.05};
  // A milling job (config/milling/*.yaml) whose cutting force acts on the plant at the spindle speed
  // (hil/cutting_load.hpp). Empty = no cut.
  std::string cut_job;
  // regenerative: the time-domain cut against the plant at one speed (hil/regenerative_cut.hpp: cut_rpm,
  // cut_axial_mm, cut_revolutions, cut_start_s; the spindle register shows its speed); forced: the rigid
  // tool's force harmonics at the spindle profile's speed (hil/cutting_load.hpp), which never regenerates.
  enum class CutModel { kRegenerative, kForced };
  CutModel cut_model{CutModel::kRegenerative};
  RegenerativeCutOptions regenerative;  // job_path = cut_job; its spindle program is the steps and ramps above
  // The regenerative cut's depth program (plant time; rpm = the depth in mm): steps and ramps.
  std::vector<SpindleChange> depth_changes;
  int cut_harmonics{12};
  // The robot moving (hil/pose_trajectory.hpp): waypoints (plant time, joint angles), the joint
  // registers written every pose_register_period_s and the plant's modes retuned every pose_update_s.
  // With a trajectory the impacts run at each dwell (two waypoints with the same pose) instead of once.
  std::vector<PoseWaypoint> pose_trajectory;
  double pose_register_period_s{0.05};
  double pose_update_s{0.02};
  bool realtime_setup{true};  // realtime pacing: SCHED_FIFO etc. (one below the loop's priority)
  // Faults injected at plant times (s; negative = none), to measure how the controller gets to its safe
  // state: the CAN bus goes off (an error frame with CAN_ERR_BUSOFF, no sensor frames for bus_off_for_s,
  // then CAN_ERR_RESTARTED, as a SocketCAN interface with restart-ms reports it), and the Modbus device
  // stops answering (requests read, never answered, for good).
  double bus_off_at_s{-1.0};
  double bus_off_for_s{0.5};
  double modbus_hang_at_s{-1.0};
  const std::atomic<int>* stop_flag{nullptr};  // SIGINT / SIGTERM
};

struct FrfReport {
  std::string name;
  double open_peak_m_per_n{0.0}, open_peak_hz{0.0};
  double closed_peak_m_per_n{0.0}, closed_peak_hz{0.0};
  double improvement_pct{0.0};
  double coherence_min{0.0};
};

struct InjectedFault {
  std::string kind;  // "bus_off", "bus_restarted", "modbus_hang"
  double plant_time_s{0.0};
  std::int64_t monotonic_ns{0};  // CLOCK_MONOTONIC, comparable with the controller's on the same machine
};

// An advice robodamp run wrote to the robot's registers (modbus.robot.advice_register), as the emulated
// robot read it, and what it did.
struct AdviceSeen {
  double plant_time_s{0.0};
  unsigned seq{0};
  int status{0};  // 1: a speed, 2: no stable speed in the range
  double rpm{0.0}, margin{0.0};
  std::string action;  // "followed", "kept the speed: no stable speed", "not followed (spindle.apply_advice
                       // false)", "refused: ..." (a value out of range)
};

struct EmulatorReport {
  std::string config;
  std::string pacing;
  std::string transport;
  std::string modbus;
  std::uint64_t ticks{0};
  double plant_time_s{0.0};
  double elapsed_s{0.0};
  std::string end_reason;
  // Frames.
  std::uint64_t sensor_frames_sent{0}, send_errors{0};
  std::uint64_t command_frames{0}, commands_lost{0}, frames_malformed{0}, frames_other{0};
  std::uint64_t held_periods{0};  // realtime: periods without a new command (the amplifier holds)
  // Amplifier and robot.
  std::uint64_t enable_changes{0};
  double enabled_s{0.0};
  double peak_temperature_c{0.0};
  double peak_command_v{0.0};
  std::uint64_t mounting_changes{0};
  std::uint64_t spindle_changes{0};
  std::uint64_t modbus_requests{0};
  // Realtime pacing: the emulator's own wake-up latency.
  rt::TimingHistogram wake_latency;
  std::uint64_t overruns{0};
  // The impact campaign.
  bool campaign_started{false}, campaign_complete{false};
  double campaign_start_s{0.0};
  int records{0}, records_planned{0};
  std::string impact_location;
  std::vector<FrfReport> frfs;
  std::vector<analysis::FrfEstimate> closed_receptance, open_receptance;  // per location
  std::vector<InjectedFault> injected;
  // robodamp measure's plant side.
  int measure_records{0}, measure_records_planned{0};
  std::vector<std::string> measure_files;
  CuttingReport cutting;
  RegenerativeCutReport regenerative_cut;
  std::vector<AdviceSeen> advice;
  // The pose trajectory: plant retunes and what each dwell measured.
  std::uint64_t pose_retunes{0};
  std::vector<PoseDwellReport> pose_dwells;
};

// Serves one controller connection and returns when it disconnects (or max_duration_s, or the stop
// flag). Throws std::runtime_error / std::system_error when it cannot set up (socket, Modbus port).
[[nodiscard]] EmulatorReport run_emulator(const config::Config& cfg, const EmulatorOptions& o);

[[nodiscard]] nlohmann::json report_json(const EmulatorReport& r);
[[nodiscard]] std::string report_text(const EmulatorReport& r);

}  // namespace robodamp::hil
