// A loop session: the configuration analysed (stability and the maximum stable gain, for the
// supervisor's arming and gain checks), the supervisor and its controller, the loop, the telemetry ring
// and its drain thread with the recorder and live timing, behind one of two backends:
// - the simulated plant in process (no can / modbus sections): the plant with the configured
//   disturbances behind drivers/sim_backend;
// - hardware (can and modbus sections): the CAN driver for the sensor and the amplifier command (a
//   PF_CAN interface, or "unix:PATH" to the HIL emulator) and the Modbus supervisory client for the
//   amplifier's enable and status and the robot's mounting, which selects among parameter_sets.
// On the virtual clock the CAN driver paces the loop in lockstep with the emulator (it waits for each
// sensor frame). `robodamp run` and the loop tests use it.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/loop_model.hpp"
#include "dds/bridge.hpp"
#include "drivers/can_driver.hpp"
#include "drivers/modbus_supervisor.hpp"
#include "drivers/sim_backend.hpp"
#include "rt/loop.hpp"
#include "rt/realtime.hpp"
#include "rt/recording.hpp"
#include "rt/telemetry_drain.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::apps {

struct SessionOptions {
  std::optional<config::ClockKind> clock;  // default: loop.clock from the configuration
  double impact_every_s{0.0};              // hammer hits at the TCP (location 1), bench.impact_peak_n; 0 = none
  bool arm_at_start{true};                 // arm once the sensor can be live
  std::string record_path;                 // empty = no recording
  bool realtime_setup{true};               // wall clock: mlockall, SCHED_FIFO, ... (config realtime)
  // The robot as it really is, when it differs from the configuration the controller was designed and
  // analysed for (another pose, a worn actuator): the plant is built from this one.
  std::optional<config::Config> plant_config;
  drivers::SimBackendOptions backend{};
  double connect_timeout_s{10.0};  // hardware: waiting for the CAN transport and the amplifier's first poll
};

// When the run lost its sensor and went safe (from the telemetry frames; loop time since the start).
struct TripTiming {
  double last_fresh_s{-1.0};  // the last fresh sensor sample before the trip
  double trip_s{-1.0};        // the first tick with a latched trip
  double safe_s{-1.0};        // the first tick after it with zero command and the amplifier enable off
};

struct RunSummary {
  std::string config;
  std::string clock;
  double rate_hz{0.0};
  double duration_s{0.0};
  rt::LoopStats loop;
  rt::SupervisorCounters supervisor;
  std::string final_state, trip, trip_description;
  double max_stable_gain_ns_per_m{0.0};
  bool analysis_stable{false};
  rt::RealtimeStatus realtime;
  std::uint64_t telemetry_frames{0};
  std::uint64_t recorded_frames{0}, record_errors{0};
  std::string backend;  // "simulated plant" or the CAN transport and Modbus endpoints
  std::optional<drivers::CanCounters> can;
  std::optional<drivers::ModbusCounters> modbus;
  std::optional<dds::BridgeCounters> dds;
  TripTiming trip_timing;
  std::string record_path;
  double sensor_rms_mps2{0.0};  // control accelerometer over the run
  double peak_command_v{0.0};
};

class Session {
 public:
  explicit Session(const config::Config& cfg, const SessionOptions& o = {});
  ~Session();

  // Before run(): more operator commands at given ticks (deterministic on the virtual clock).
  void schedule(std::uint64_t tick, const rt::OperatorCommand& c) { loop_->schedule(tick, c); }
  // Before run(): another controller parameter set (designed and analysed from cfg, same loop rate)
  // that a select_params command may hand over to. Returns its index.
  std::size_t add_parameter_set(const config::Config& cfg);
  // From any non-real-time thread while running: an operator command for the next tick boundary.
  bool post(const rt::OperatorCommand& c) { return loop_->post(c); }
  // The parameter set for a mounting (set 0 is the configuration's own), if there is one.
  [[nodiscard]] std::optional<std::size_t> parameter_set_for(config::Mounting m) const;
  [[nodiscard]] bool hardware() const { return can_ != nullptr; }
  // A parameter request (DDS): validated as the configuration validates its values, then queued.
  [[nodiscard]] dds::Decision handle_request(dds::RequestKind kind, double value);
  [[nodiscard]] drivers::CanDriver* can_driver() { return can_.get(); }
  [[nodiscard]] drivers::ModbusSupervisor* modbus() { return modbus_.get(); }
  // Runs for duration_s of loop time on a thread of its own (set up for real time on the wall clock),
  // then disarms to the safe state; blocks until done.
  RunSummary run(double duration_s);

  [[nodiscard]] sim::Plant& plant() { return *plant_; }  // simulated backend only
  [[nodiscard]] drivers::SimBackend& backend() { return *backend_; }
  [[nodiscard]] rt::Supervisor& supervisor() { return *supervisor_; }
  [[nodiscard]] rt::Loop& loop() { return *loop_; }
  [[nodiscard]] rt::SpscRing<rt::TelemetryFrame>& telemetry_ring() { return *ring_; }
  [[nodiscard]] const analysis::LoopModel& model() const { return *model_; }
  [[nodiscard]] const config::Config& config() const { return cfg_; }
  // All frames drained in this session (kept in memory for tests when asked).
  void keep_frames(bool on) { keep_frames_ = on; }
  [[nodiscard]] const std::vector<rt::TelemetryFrame>& frames() const { return frames_; }

 private:
  config::Config cfg_;
  SessionOptions o_;
  std::unique_ptr<analysis::LoopModel> model_;
  std::optional<double> max_stable_gain_;
  bool stable_{false};
  std::unique_ptr<sim::Plant> plant_;
  std::unique_ptr<drivers::SimBackend> backend_;
  std::unique_ptr<drivers::CanDriver> can_;
  std::unique_ptr<drivers::ModbusSupervisor> modbus_;
  rt::SensorSource* sensor_{nullptr};
  rt::ActuatorSink* actuator_{nullptr};
  rt::SupervisoryIo* io_{nullptr};
  std::vector<std::pair<config::Mounting, std::size_t>> mounting_sets_;
  std::string backend_name_;
  std::unique_ptr<rt::Supervisor> supervisor_;
  std::unique_ptr<rt::SpscRing<rt::TelemetryFrame>> ring_;
  std::unique_ptr<rt::Loop> loop_;
  bool keep_frames_{false};
  std::vector<rt::TelemetryFrame> frames_;
};

[[nodiscard]] nlohmann::json summary_json(const RunSummary& s);
[[nodiscard]] std::string summary_text(const RunSummary& s);

}  // namespace robodamp::apps
