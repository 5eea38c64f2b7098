#include "drivers/sim_backend.hpp"

#include "rt/clock.hpp"

namespace robodamp::drivers {

void SimBackend::advance_to(std::uint64_t tick) noexcept {
  const sim::PlantCounters before = plant_.counters();
  while (plant_.counters().steps < tick) {
    const std::uint64_t m = plant_.counters().steps;  // the period [m, m+1)
    // Driven by the command written at tick m-1 or earlier (one sample of computation delay).
    double v = 0.0;
    if (any_written_) v = written_tick_ + 1 <= m ? written_v_ : previous_v_;
    applied_v_ = enabled_ ? v : 0.0;
    if (hook_ != nullptr) hook_->before_step(m);
    plant_.step(applied_v_);
    if (hook_ != nullptr) hook_->after_step(m);
  }
  const sim::PlantCounters& after = plant_.counters();
  saturated_ = after.force_limited != before.force_limited || after.voltage_clipped != before.voltage_clipped;
}

rt::SensorSample SimBackend::read(std::uint64_t tick) noexcept {
  advance_to(tick);
  const double t = plant_.time_s();
  auto& faults = plant_.faults();
  if (faults.active(sim::FaultKind::kDriverStall, t)) {  // a driver call that blocks: real time passes
    const double until = rt::monotonic_s() + faults.magnitude(sim::FaultKind::kDriverStall, t);
    while (rt::monotonic_s() < until) {}
  }
  const sim::SensorReading r = plant_.sense();
  return {r.accel_mps2, r.fresh, !faults.active(sim::FaultKind::kSensorDriverError, t)};
}

rt::ActuatorStatus SimBackend::write(double command_v, std::uint64_t tick) noexcept {
  previous_v_ = any_written_ ? written_v_ : 0.0;
  written_v_ = command_v;
  written_tick_ = tick;
  any_written_ = true;
  return {!plant_.faults().active(sim::FaultKind::kActuatorDriverError, plant_.time_s()), saturated_};
}

void SimBackend::request_amplifier_enable(bool on) noexcept {
  if (on && !enabled_) enabled_at_s_ = plant_.time_s();
  enabled_ = on;
}

rt::AmplifierStatus SimBackend::amplifier_status() noexcept {
  const double t = plant_.time_s();
  rt::AmplifierStatus s;
  s.enabled = enabled_;
  s.fault = plant_.faults().active(sim::FaultKind::kAmplifierFault, t);
  s.ready = enabled_ && !s.fault && t >= enabled_at_s_ + o_.amplifier_ready_delay_s;
  s.temperature_c = o_.amplifier_temperature_c;
  return s;
}

}  // namespace robodamp::drivers
