// The composition root: a robot cell built from one configuration, with an explicit lifecycle.
//
//   Cell cell(cfg, options);
//   cell.configure();    analyse the loop (stability, K_max), load and analyse parameter_sets, configure
//                        the devices (simulated plant, or CAN bus + Modbus client), DDS, the supervisor,
//                        the loop, the arming policy. May allocate; reports every problem as a Status.
//   cell.activate(T);    recorder, telemetry drain, devices started (Modbus polling and the amplifier's
//                        first answer, the CAN queue flushed), DDS, then the loop thread (set up for real
//                        time on the wall clock) for T seconds of loop time.
//   cell.wait();         until the loop has ended (its duration, request_stop, a signal, or the arming
//                        policy giving up) and is safe.
//   cell.deactivate();   stop the loop through the safe state if it still runs, drain, amplifier off,
//                        devices and DDS stopped, the run summary filled in.
//   cell.cleanup();      devices closed.
// run(T) is activate + wait + deactivate. The destructor deactivates and cleans up on every path, so a
// test that returns early never leaves a thread running.
//
// Backends: no can/modbus sections: the simulated plant in process (runtime/components.hpp), paced by
// the loop's clock; can + modbus: the CAN driver for the sensor and the amplifier command and the Modbus
// client for the amplifier's enable and status and the robot's mounting, which selects among
// parameter_sets. On the virtual clock the CAN driver paces the loop in lockstep with the HIL emulator.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "analysis/loop_model.hpp"
#include "analysis/pose_schedule.hpp"
#include "rt/loop.hpp"
#include "rt/realtime.hpp"
#include "rt/recording.hpp"
#include "rt/telemetry_drain.hpp"
#include "runtime/arming_policy.hpp"
#include "runtime/components.hpp"
#include "runtime/lifecycle.hpp"
#include "runtime/joint_state_pose.hpp"
#include "runtime/path_ahead.hpp"
#include "runtime/machining_monitor.hpp"
#include "runtime/spectrum_monitor.hpp"
#include "runtime/run_summary.hpp"

namespace robodamp::runtime {

struct CellOptions {
  std::optional<config::ClockKind> clock;  // default: loop.clock from the configuration
  double impact_every_s{0.0};              // simulated plant: hammer hits at the TCP (bench.impact_peak_n); 0 = none
  bool arm_at_start{true};                 // the arming policy arms (and retries) once the sensor can be live
  std::string record_path;                 // empty = no recording
  bool realtime_setup{true};               // wall clock: mlockall, SCHED_FIFO, ... (config realtime)
  // The robot as it really is, when it differs from the configuration the controller was designed and
  // analysed for (another pose, a worn actuator): the simulated plant is built from this one.
  std::optional<config::Config> plant_config;
  drivers::SimBackendOptions backend{};
  double connect_timeout_s{10.0};  // hardware: waiting for the CAN transport and the amplifier's first poll
  bool keep_frames{false};         // keep every drained frame in memory (tests)
  rt::PeriodicChirp chirp{};       // robodamp measure: the loop's chirp added to the command while active
  // pose_schedule (analysis/pose_schedule.hpp):
  //  - pose_deg: the robot stands at this pose (simulated backend: the plant is the robot model there and
  //    the pose is reported to the supervisor at tick 0);
  //  - pose_schedule_off: region 0's set runs at every pose and the joint angles are not read (what a
  //    damper tuned at one pose does elsewhere).
  std::vector<double> pose_deg;
  bool pose_schedule_off{false};
  // With pose_schedule_off: the joints are still read (robot_pose_deg), no set follows them (measure
  // --along-path: the gain is 0 and a pose outside every region is worth measuring).
  bool watch_joints{false};
  // Every drained frame, on the drain thread (progress lines); must not block for long.
  std::function<void(const rt::TelemetryFrame&)> on_frame;
};

class Cell {
 public:
  explicit Cell(const config::Config& cfg, CellOptions o = {});
  ~Cell();
  Cell(const Cell&) = delete;
  Cell& operator=(const Cell&) = delete;

  Status configure();
  Status activate(double duration_s);
  void wait();
  Status deactivate();
  Status cleanup();
  // activate + wait + deactivate, from Inactive: the activation's Status (the run's result in summary()).
  [[nodiscard]] Status run(double duration_s);
  [[nodiscard]] LifecycleState state() const noexcept { return state_; }

  // Inactive (configured): another controller parameter set (designed and analysed from cfg, same loop
  // rate) that a select_params command may hand over to. Returns its index.
  std::size_t add_parameter_set(const config::Config& cfg, bool own_schedule = true);
  // Inactive: an operator command at a given tick (deterministic on the virtual clock).
  void schedule(std::uint64_t tick, const rt::OperatorCommand& c) { loop_->schedule(tick, c); }
  // Active, any non-real-time thread: an operator command for the next tick boundary.
  bool post(const rt::OperatorCommand& c) { return loop_->post(c); }
  // Active, any thread: end the run early through the safe state.
  void request_stop() noexcept;
  // A parameter request (DDS): validated as the configuration validates its values, then queued.
  [[nodiscard]] dds::Decision handle_request(dds::RequestKind kind, double value);
  // pose_schedule: each region's set and analysis (empty without a schedule).
  [[nodiscard]] const analysis::PoseScheduleAnalysis& pose_schedule() const { return pose_schedule_; }
  // The parameter set for a mounting (set 0 is the configuration's own), if there is one.
  [[nodiscard]] std::optional<std::size_t> parameter_set_for(config::Mounting m) const;

  [[nodiscard]] bool hardware() const { return can_ != nullptr; }
  [[nodiscard]] const std::string& backend_name() const { return backend_name_; }
  [[nodiscard]] const RunSummary& summary() const { return summary_; }
  // The simulated backend's plant and devices; on the hardware backend (hardware()) they do not exist and
  // these throw std::logic_error saying so.
  [[nodiscard]] sim::Plant& plant();
  [[nodiscard]] drivers::SimBackend& sim_backend();
  [[nodiscard]] drivers::CanDriver* can_driver() { return can_ ? &can_->driver() : nullptr; }
  [[nodiscard]] drivers::ModbusClient* modbus() { return modbus_ ? &modbus_->client() : nullptr; }
  [[nodiscard]] rt::Supervisor& supervisor() { return *supervisor_; }
  [[nodiscard]] rt::Loop& loop() { return *loop_; }
  [[nodiscard]] ArmingPolicy& arming() { return *arming_; }
  [[nodiscard]] rt::SpscRing<rt::TelemetryFrame>& telemetry_ring() { return *ring_; }
  [[nodiscard]] const analysis::LoopModel& model() const { return *model_; }
  [[nodiscard]] const config::Config& config() const { return cfg_; }
  [[nodiscard]] const std::vector<rt::TelemetryFrame>& frames() const { return frames_; }
  // The robot's joints now (any thread): the DDS joint states, else the Modbus joint registers, else the
  // simulated robot's --pose; empty while not known.
  [[nodiscard]] std::vector<double> robot_pose_deg() const;
  // With spindle.job: the live machining view (nullptr without).
  [[nodiscard]] MachiningMonitor* machining() { return machining_.get(); }

 private:
  Status plan_analysis();               // configure(): the analysis and the supervisor
  Status compose_devices();             // configure(): the devices, the loop and what runs beside it
  dds::BridgeSources bridge_sources();  // what the DDS bridge publishes and whom it calls (runtime/cell_dds.cpp)
  void release();                       // configure's rollback and cleanup(): everything configure built
  Status configure_devices();
  Status configure_parameter_sets();
  Status configure_pose_schedule();  // before the supervisor: region 0's set becomes set 0
  void configure_pose_sets();        // after it: regions 1.. as sets 1..
  void post_pose_region(std::optional<std::size_t> region);
  // The spectrum monitor's next spectrum; with pose_schedule and a known pose its mode marks are the robot
  // model's modes along the actuator at that pose (the configuration's table otherwise).
  [[nodiscard]] std::optional<dds::SpectrumSample> spectrum_at_pose();
  std::vector<Component*> components();
  void on_frame(const rt::TelemetryFrame& f);
  void finish_summary();

  config::Config cfg_;
  CellOptions o_;
  LifecycleState state_{LifecycleState::kUnconfigured};
  std::unique_ptr<analysis::LoopModel> model_;
  std::optional<double> max_stable_gain_;
  bool stable_{false};
  std::unique_ptr<SimBackendComponent> sim_;
  std::unique_ptr<CanBus> can_;
  std::unique_ptr<ModbusComponent> modbus_;
  std::unique_ptr<JointStatePose> joint_pose_;  // dds.joint_states: the pose from a ROS 2 driver (outlives dds_)
  std::unique_ptr<PathAhead> path_ahead_;       // dds.path_ahead: the robot program's next poses (outlives dds_)
  std::unique_ptr<DdsEndpoint> dds_;
  std::vector<std::pair<config::Mounting, std::size_t>> mounting_sets_;
  std::string backend_name_;
  std::unique_ptr<rt::Supervisor> supervisor_;
  std::unique_ptr<rt::SpscRing<rt::TelemetryFrame>> ring_;
  std::unique_ptr<rt::Loop> loop_;
  std::unique_ptr<ArmingPolicy> arming_;
  std::vector<config::Config> set_configs_;               // every parameter set's configuration, index = set
  std::unique_ptr<SpectrumMonitor> spectrum_;             // dds: the accelerometer's spectrum for the operator's screen
  std::unique_ptr<MachiningMonitor> machining_;           // spindle.job: live stability and the chatter indicator
  analysis::PoseScheduleAnalysis pose_schedule_;          // region i's set is supervisor set i
  static constexpr double kMachiningSummaryWaitS = 30.0;  // for the limits at the last state (worker thread)

  // Active run.
  std::optional<rt::RealtimeProcess> rt_process_;
  std::unique_ptr<rt::Recorder> recorder_;
  std::unique_ptr<rt::TelemetryDrain> drain_;
  std::thread loop_thread_;
  RunSummary summary_;
  double sum_sq_{0.0};
  std::uint64_t n_samples_{0};
  std::int64_t n_frames_{0}, last_fresh_frame_{-1};
  // The loop's state, trip and derating as the drain last saw them: each change is logged when it happens.
  std::uint8_t seen_state_{255}, seen_trip_{0};
  bool seen_derated_{false};
  void log_changes(const rt::TelemetryFrame& f);
  std::optional<rt::AvailabilityMeter> availability_;  // fed on the drain thread
  std::vector<rt::TelemetryFrame> frames_;
};

}  // namespace robodamp::runtime
