#include "sim_plant/faults.hpp"

namespace robodamp::sim {

const char* to_string(FaultKind kind) {
  switch (kind) {
    case FaultKind::kSensorDropout:
      return "sensor_dropout";
    case FaultKind::kSensorStuck:
      return "sensor_stuck";
    case FaultKind::kSensorSpike:
      return "sensor_spike";
    case FaultKind::kSensorNan:
      return "sensor_nan";
    case FaultKind::kActuatorDead:
      return "actuator_dead";
    case FaultKind::kActuatorSaturated:
      return "actuator_saturated";
    case FaultKind::kAmplifierFault:
      return "amplifier_fault";
    case FaultKind::kSensorDriverError:
      return "sensor_driver_error";
    case FaultKind::kActuatorDriverError:
      return "actuator_driver_error";
    case FaultKind::kDriverStall:
      return "driver_stall";
  }
  return "?";
}

}  // namespace robodamp::sim
