// The loop's driver interfaces: a sensor source, an actuator sink and the supervisory I/O (amplifier
// enable and status). The loop calls them once per tick from the real-time thread, so every
// implementation's calls are non-blocking, allocation-free and noexcept; a driver that talks to a slow
// device (Modbus) does that in its own thread and answers here from what it last saw.
// Implementations: drivers/sim_backend (the simulated plant); hardware drivers build on the same.
#pragma once

#include <cstdint>

namespace robodamp::rt {

struct SensorSample {
  double accel_mps2{0.0};  // at the actuator location, in the controller's frame
  bool fresh{false};       // a new sample since the last tick (not a repeat of an old one)
  bool ok{true};           // the driver reports no fault (bus, device, decoding)
};

class SensorSource {
 public:
  virtual ~SensorSource() = default;
  // The sample for loop tick `tick` (ticks count nominal periods from 0; missed ticks are skipped).
  [[nodiscard]] virtual SensorSample read(std::uint64_t tick) noexcept = 0;
};

struct ActuatorStatus {
  bool ok{true};          // the command was delivered
  bool saturated{false};  // the amplifier or actuator clipped what it was asked for
};

class ActuatorSink {
 public:
  virtual ~ActuatorSink() = default;
  // The amplifier command for tick `tick`, volts.
  [[nodiscard]] virtual ActuatorStatus write(double command_v, std::uint64_t tick) noexcept = 0;
};

struct AmplifierStatus {
  bool enabled{false};  // the enable the amplifier last acknowledged
  bool ready{false};    // enabled and able to drive
  bool fault{false};    // the amplifier reports a fault (over-temperature, over-current)
  // Its status is unknown while it is needed (the supervisory link lost): the loop cannot deliver the
  // command with certainty, an actuator-path fault the supervisor may recover from once the link is back.
  bool link_lost{false};
  double temperature_c{0.0};
};

class AmplifierIo {
 public:
  virtual ~AmplifierIo() = default;
  // Asks for the amplifier enable state; takes effect when the device acknowledges it.
  virtual void request_amplifier_enable(bool on) noexcept = 0;
  [[nodiscard]] virtual AmplifierStatus amplifier_status() noexcept = 0;
};

}  // namespace robodamp::rt
