#include "sim_plant/faults.hpp"

namespace robodamp::sim {

const char* to_string(FaultKind kind) {
  switch (kind) {
    case FaultKind::kSensorDropout: return "sensor_dropout";
    case FaultKind::kSensorStuck: return "sensor_stuck";
    case FaultKind::kSensorSpike: return "sensor_spike";
    case FaultKind::kSensorNan: return "sensor_nan";
    case FaultKind::kActuatorDead: return "actuator_dead";
    case FaultKind::kActuatorSaturated: return "actuator_saturated";
  }
  return "?";
}

}  // namespace robodamp::sim
