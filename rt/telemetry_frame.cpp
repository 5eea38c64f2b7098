#include "rt/telemetry_frame.hpp"

namespace robodamp::rt {

const char* to_string(FieldType t) {
  switch (t) {
    case FieldType::kU8:
      return "u8";
    case FieldType::kU16:
      return "u16";
    case FieldType::kU32:
      return "u32";
    case FieldType::kU64:
      return "u64";
    case FieldType::kF32:
      return "f32";
    case FieldType::kF64:
      return "f64";
  }
  return "?";
}

#define RD_FIELD(name, type, unit) \
  FieldInfo { #name, FieldType::type, offsetof(TelemetryFrame, name), unit }

const std::array<FieldInfo, 21>& frame_fields() {
  static const std::array<FieldInfo, 21> fields{
      RD_FIELD(tick, kU64, "tick"),
      RD_FIELD(time_s, kF64, "s"),
      RD_FIELD(dt_s, kF64, "s"),
      RD_FIELD(accel_mps2, kF64, "m/s^2"),
      RD_FIELD(filtered_mps, kF64, "m/s"),
      RD_FIELD(controller_v, kF64, "V"),
      RD_FIELD(command_v, kF64, "V"),
      RD_FIELD(gain_ns_per_m, kF64, "N s/m"),
      RD_FIELD(command_value, kF64, "(per command)"),
      RD_FIELD(wake_latency_us, kF32, "us"),
      RD_FIELD(compute_us, kF32, "us"),
      RD_FIELD(missed_ticks, kU32, "ticks"),
      RD_FIELD(overruns, kU32, "ticks"),
      RD_FIELD(saturated_ticks, kU32, "ticks"),
      RD_FIELD(ring_drops, kU32, "frames"),
      RD_FIELD(stale_ticks, kU32, "ticks"),
      RD_FIELD(invalid_samples, kU32, "samples"),
      RD_FIELD(flags, kU16, "bits"),
      RD_FIELD(state, kU8, "enum"),
      RD_FIELD(trip, kU8, "enum"),
      RD_FIELD(command_kind, kU8, "enum"),
  };
  return fields;
}

#undef RD_FIELD

TickInput tick_input(const TelemetryFrame& f) {
  TickInput in;
  in.dt_s = f.dt_s;
  in.accel_mps2 = f.accel_mps2;
  in.fresh = (f.flags & kFlagFresh) != 0;
  in.sensor_ok = (f.flags & kFlagSensorOk) != 0;
  in.actuator_ok = (f.flags & kFlagActuatorOk) != 0;
  in.actuator_saturated = (f.flags & kFlagActuatorSaturated) != 0;
  in.amplifier_ready = (f.flags & kFlagAmplifierReady) != 0;
  in.amplifier_fault = (f.flags & kFlagAmplifierFault) != 0;
  in.overrun = (f.flags & kFlagOverrun) != 0;
  in.shutdown = (f.flags & kFlagShutdown) != 0;
  in.command = {static_cast<CommandKind>(f.command_kind), f.command_value};
  return in;
}

}  // namespace robodamp::rt
