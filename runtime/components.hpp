// The devices of a cell as lifecycle components (runtime/lifecycle.hpp): what each one does on
// configure, activate, deactivate and cleanup. The loop reaches them only through rt/io.hpp.
//
//   component            configure                      activate                         deactivate
//   SimBackendComponent  build the plant and drives     -                                -
//   CanBus               open the channel, the driver   flush the queue (wall clock) or  stop reconnecting
//                                                       lockstep wait (virtual clock);
//                                                       unix: transport: reconnect thread
//   ModbusComponent      the client, register maps      start polling, wait for the      amplifier enable off,
//                                                       amplifier's first answer         stop polling
//   DdsEndpoint          participant and topics         status thread                    last status, stop
#pragma once

#include <functional>
#include <mutex>
#include <stop_token>
#include <memory>
#include <optional>
#include <string>

#include "config/config.hpp"
#include "dds/bridge.hpp"
#include "drivers/can_driver.hpp"
#include "drivers/modbus_client.hpp"
#include "drivers/sim_backend.hpp"
#include "rt/io.hpp"
#include "runtime/lifecycle.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"
#include "threads/worker.hpp"

namespace robodamp::runtime {

// The simulated backend in process (drivers::SimBackend over sim::Plant): sensor, actuator and amplifier in one.
class SimBackendComponent final : public Component {
 public:
  // model: the plant the controller was designed for; plant_cfg: the robot as it really is.
  SimBackendComponent(const sim::PlantModel& model, const config::Config& plant_cfg, drivers::SimBackendOptions o);
  [[nodiscard]] sim::Plant& plant() { return *plant_; }
  [[nodiscard]] drivers::SimBackend& backend() { return *backend_; }

 private:
  Status on_configure() override;
  Status on_cleanup() override;
  sim::PlantModel model_;
  config::Config cfg_;
  drivers::SimBackendOptions o_;
  std::unique_ptr<sim::Plant> plant_;
  std::unique_ptr<drivers::SimBackend> backend_;
};

// The CAN bus: the sensor frames in and the amplifier command out. On a unix: transport (the HIL
// emulator) a thread reconnects when the peer has gone and is listening again (an emulator restarted):
// the driver takes the new connection over at its next read; the supervisor's trip stays latched until
// an operator resets it.
class CanBus final : public Component {
 public:
  CanBus(const config::CanConfig& cfg, double rate_hz, config::ClockKind clock, double connect_timeout_s);
  ~CanBus() override;
  [[nodiscard]] drivers::CanDriver& driver() { return *driver_; }

 private:
  Status on_configure() override;
  Status on_activate() override;
  Status on_deactivate() override;
  Status on_cleanup() override;
  void reconnect_loop(std::stop_token stop);
  void stop_reconnecting();
  config::CanConfig cfg_;
  double rate_hz_;
  config::ClockKind clock_;
  double connect_timeout_s_;
  std::unique_ptr<drivers::CanDriver> driver_;
  std::uint64_t flushed_{0};
  threads::Worker reconnect_;  // a lost unix: link dialled again every 20 ms (last: stopped before the driver goes)
};

// The Modbus client (drivers::ModbusClient): amplifier enable, ready, fault, temperature; the robot's mounting.
class ModbusComponent final : public Component {
 public:
  ModbusComponent(const config::ModbusConfig& cfg, config::Mounting initial,
                  drivers::ModbusClient::MountingCallback on_mounting, double connect_timeout_s);
  // Between on_configure and on_cleanup only (the loop's thread and the lifecycle's).
  [[nodiscard]] drivers::ModbusClient& client() { return *client_; }
  // Any thread, in any state (the machining monitor's advisor runs from the cell's configure on, before
  // this component's on_configure and until the cell's cleanup): nothing while there is no client.
  void publish_advice(std::uint64_t seq, bool found, double rpm, double margin);
  void withdraw_advice(std::uint64_t seq);
  [[nodiscard]] double robot_depth_mm() const;  // NaN without a client

 private:
  Status on_configure() override;
  Status on_activate() override;
  Status on_deactivate() override;
  Status on_cleanup() override;
  mutable std::mutex client_m_;  // guards client_'s creation and reset against the two calls above
  config::ModbusConfig cfg_;
  config::Mounting initial_;
  drivers::ModbusClient::MountingCallback on_mounting_;
  double connect_timeout_s_;
  std::unique_ptr<drivers::ModbusClient> client_;
  bool answered_{false};
};

// The DDS bridge: telemetry, status and supervised parameter requests (fed by the telemetry drain).
class DdsEndpoint final : public Component {
 public:
  DdsEndpoint(const config::DdsConfig& cfg, double rate_hz, std::string source, dds::BridgeSources sources);
  [[nodiscard]] dds::Bridge& bridge() { return *bridge_; }

 private:
  Status on_configure() override;
  Status on_activate() override;
  Status on_deactivate() override;
  Status on_cleanup() override;
  config::DdsConfig cfg_;
  double rate_hz_;
  std::string source_;
  dds::BridgeSources sources_;
  std::unique_ptr<dds::Bridge> bridge_;
};

}  // namespace robodamp::runtime
