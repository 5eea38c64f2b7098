// Scheduled faults for safety work: the sensor drops out, sticks, spikes or reads NaN; the actuator goes
// dead or saturates at a lower force; and faults of the path to the devices, which the simulated backend
// (drivers/sim_backend) reports through the driver interfaces: the amplifier signals a fault, the sensor's
// or the actuator's driver reports an error, a driver call stalls the loop (magnitude = seconds per call). Faults are added before a run; queries are RT-safe.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace robodamp::sim {

enum class FaultKind {
  kSensorDropout,
  kSensorStuck,
  kSensorSpike,
  kSensorNan,
  kActuatorDead,
  kActuatorSaturated,
  kAmplifierFault,
  kSensorDriverError,
  kActuatorDriverError,
  kDriverStall,
};

[[nodiscard]] const char* to_string(FaultKind kind);

struct Fault {
  FaultKind kind{FaultKind::kSensorDropout};
  double start_s{0.0};
  double duration_s{std::numeric_limits<double>::infinity()};
  double magnitude{0.0};  // spike: m/s^2 added; actuator saturated: force limit (N)
  double period_s{0.0};   // spike: repeat period within the window (0 = once)
};

// What the sensor delivers for one tick: a value and whether it is a new sample.
struct SensorReading {
  double accel_mps2{0.0};
  bool fresh{true};
};

class FaultInjector {
 public:
  void add(const Fault& f) {
    faults_.push_back(f);
    next_spike_s_.push_back(f.start_s);
  }
  void clear() {
    faults_.clear();
    next_spike_s_.clear();
  }
  [[nodiscard]] bool empty() const { return faults_.empty(); }

  // RT-safe. The reading at time t for a measured value; stuck holds the value measured when the fault
  // began, dropout repeats the last delivered value marked not fresh.
  SensorReading apply_sensor(double t_s, double dt_s, double value) noexcept {
    SensorReading r{value, true};
    for (std::size_t i = 0; i < faults_.size(); ++i) {
      const Fault& f = faults_[i];
      if (!active(f, t_s)) continue;
      switch (f.kind) {
        case FaultKind::kSensorDropout:
          r = {last_.accel_mps2, false};
          break;
        case FaultKind::kSensorStuck:
          if (!stuck_) stuck_value_ = last_.accel_mps2, stuck_ = true;
          r.accel_mps2 = stuck_value_;
          break;
        case FaultKind::kSensorSpike:
          // One sample per due time: at the start, then every period.
          if (t_s >= next_spike_s_[i]) {
            r.accel_mps2 += f.magnitude;
            next_spike_s_[i] =
                f.period_s > 0.0
                    ? next_spike_s_[i] + f.period_s * std::ceil((t_s - next_spike_s_[i] + 0.5 * dt_s) / f.period_s)
                    : std::numeric_limits<double>::infinity();
          }
          break;
        case FaultKind::kSensorNan:
          r.accel_mps2 = std::numeric_limits<double>::quiet_NaN();
          break;
        default:
          break;
      }
    }
    if (!any_active(FaultKind::kSensorStuck, t_s)) stuck_ = false;
    last_ = r;
    return r;
  }
  // RT-safe. Whether a fault of this kind is active at time t, and the largest magnitude among them.
  [[nodiscard]] bool active(FaultKind k, double t_s) const noexcept { return any_active(k, t_s); }
  [[nodiscard]] double magnitude(FaultKind k, double t_s) const noexcept {
    double m = 0.0;
    for (const auto& f : faults_)
      if (f.kind == k && active(f, t_s)) m = std::max(m, f.magnitude);
    return m;
  }
  // RT-safe. Actuator force limit at time t (0 when dead), given the nominal one.
  [[nodiscard]] double actuator_force_limit_n(double t_s, double nominal_n) const noexcept {
    double limit = nominal_n;
    for (const auto& f : faults_) {
      if (!active(f, t_s)) continue;
      if (f.kind == FaultKind::kActuatorDead) limit = 0.0;
      if (f.kind == FaultKind::kActuatorSaturated) limit = std::min(limit, f.magnitude);
    }
    return limit;
  }

 private:
  static bool active(const Fault& f, double t_s) noexcept { return t_s >= f.start_s && t_s < f.start_s + f.duration_s; }
  [[nodiscard]] bool any_active(FaultKind k, double t_s) const noexcept {
    for (const auto& f : faults_)
      if (f.kind == k && active(f, t_s)) return true;
    return false;
  }
  std::vector<Fault> faults_;
  std::vector<double> next_spike_s_;
  SensorReading last_{};
  bool stuck_{false};
  double stuck_value_{0.0};
};

}  // namespace robodamp::sim
