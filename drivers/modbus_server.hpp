// A Modbus TCP server (libmodbus) on its own thread: what the plant emulator (robodamp plant) serves
// the amplifier's and the robot controller's registers with, and what the Modbus tests talk to. Several
// clients at once (select), register access from other threads under a lock, and the failures a
// device shows: hanging (requests received, never answered) and dropping every connection.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <stop_token>
#include <string>
#include <vector>

#include "threads/worker.hpp"

// libmodbus's own names (its modbus.h), declared here so that the header does not pull libmodbus in.
typedef struct _modbus modbus_t;                    // NOLINT(bugprone-reserved-identifier)
typedef struct _modbus_mapping_t modbus_mapping_t;  // NOLINT(bugprone-reserved-identifier)

namespace robodamp::drivers {

class ModbusServer {
 public:
  struct Sizes {
    int coils{256}, discrete_inputs{256}, holding_registers{256}, input_registers{256};
  };
  explicit ModbusServer(Sizes sizes);
  ModbusServer() : ModbusServer(Sizes{}) {}
  ~ModbusServer();
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  // Listens on host:port (0 = a free port) and serves until stop(). Returns the port. Throws
  // std::runtime_error naming the address when it cannot listen.
  int start(const std::string& host, int port);
  void stop();
  [[nodiscard]] int port() const { return port_; }

  [[nodiscard]] bool coil(int address) const;
  void set_coil(int address, bool on);
  void set_discrete_input(int address, bool on);
  void set_input_register(int address, std::uint16_t value);
  [[nodiscard]] std::uint16_t holding_register(int address) const;
  void set_holding_register(int address, std::uint16_t value);

  // false: requests are read and never answered (clients time out).
  void set_responding(bool on) { responding_.store(on); }
  // Closes every client connection (a pulled cable, a device reset); new connections are accepted.
  void drop_clients() { drop_.store(true); }
  [[nodiscard]] std::uint64_t requests() const { return requests_.load(); }
  [[nodiscard]] std::uint64_t connections() const { return connections_.load(); }

 private:
  void serve(std::stop_token stop);
  modbus_t* ctx_{nullptr};
  modbus_mapping_t* map_{nullptr};
  mutable std::mutex m_;
  int listen_fd_{-1};
  int port_{0};
  std::vector<int> clients_;
  std::atomic<bool> responding_{true}, drop_{false};
  std::atomic<std::uint64_t> requests_{0}, connections_{0};
  threads::Worker worker_;  // the select loop (last: stopped before what it serves goes)
};

}  // namespace robodamp::drivers
