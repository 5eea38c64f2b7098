// The simulated plant behind the loop's driver interfaces: the backend for bench runs, real-time
// simulation and tests. The plant advances one loop period per tick (through skipped ticks too, holding
// the amplifier's last command, as an amplifier does). A command written at tick k drives the plant from
// tick k+1 on: the one-sample computation delay the loop analysis assumes (analysis/loop_model.hpp), as
// with a DAQ that latches its outputs at the next sample clock. The amplifier is enabled on request and
// ready after a delay; with it disabled the actuator gets no drive. Faults of the path come from the
// plant's fault injector: amplifier fault, sensor / actuator driver errors, a stalling driver call.
#pragma once

#include <cstdint>

#include "rt/io.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::drivers {

// Called around every plant period (the plant-side instruments of robodamp measure: the hammer's load
// cell and the measurement accelerometers). k = the period's index. RT-safe implementations only.
class PlantStepHook {
 public:
  virtual ~PlantStepHook() = default;
  virtual void before_step(std::uint64_t k) noexcept = 0;
  virtual void after_step(std::uint64_t k) noexcept = 0;
};

struct SimBackendOptions {
  double amplifier_ready_delay_s{0.005};
  double amplifier_temperature_c{35.0};
};

class SimBackend final : public rt::SensorSource, public rt::ActuatorSink, public rt::AmplifierIo {
 public:
  explicit SimBackend(sim::Plant& plant, SimBackendOptions o = {}) : plant_(plant), o_(o) {}

  [[nodiscard]] rt::SensorSample read(std::uint64_t tick) noexcept override;
  [[nodiscard]] rt::ActuatorStatus write(double command_v, std::uint64_t tick) noexcept override;
  void request_amplifier_enable(bool on) noexcept override;
  [[nodiscard]] rt::AmplifierStatus amplifier_status() noexcept override;

  [[nodiscard]] sim::Plant& plant() noexcept { return plant_; }
  [[nodiscard]] double applied_v() const noexcept { return applied_v_; }  // drive of the last plant period
  // Before activation: instruments stepped with the plant (nullptr = none).
  void set_step_hook(PlantStepHook* hook) noexcept { hook_ = hook; }

 private:
  void advance_to(std::uint64_t tick) noexcept;

  sim::Plant& plant_;
  SimBackendOptions o_;
  double written_v_{0.0}, previous_v_{0.0};
  std::uint64_t written_tick_{0};
  bool any_written_{false};
  double applied_v_{0.0};
  bool saturated_{false};
  bool enabled_{false};
  double enabled_at_s_{0.0};
  PlantStepHook* hook_{nullptr};
};

}  // namespace robodamp::drivers
