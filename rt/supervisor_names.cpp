// The supervisor's states, trips, refusals, events and commands by name: what logs, summaries, recordings and
// the DDS status say.
#include "rt/supervisor.hpp"

namespace robodamp::rt {

const char* to_string(State s) {
  switch (s) {
    case State::kDisabled:
      return "disabled";
    case State::kArming:
      return "arming";
    case State::kActive:
      return "active";
    case State::kStopping:
      return "stopping";
    case State::kFault:
      return "fault";
  }
  return "?";
}

const char* to_string(Trip t) { return trip_name(t).data(); }  // kTripNames: literals, each ends in a NUL

const char* describe(Trip t) {
  switch (t) {
    case Trip::kNone:
      return "no fault";
    case Trip::kSensorStale:
      return "no fresh accelerometer sample for supervision.stale_sensor_cycles ticks: check the sensor node and its "
             "bus";
    case Trip::kSampleInvalid:
      return "non-finite or out-of-range acceleration samples: check the sensor, its cable and "
             "supervision.sample_limit_mps2";
    case Trip::kOverruns:
      return "consecutive loop overruns: the loop cannot keep its rate on this machine (see the timing statistics; "
             "isolate a CPU, lower loop.rate_hz)";
    case Trip::kSaturation:
      return "actuator at its limit for more than supervision.saturation_duty_max of the window: the disturbance is "
             "too large for the actuator, or the gain too high";
    case Trip::kInstability:
      return "growing oscillation in the loop: the gain is too high for this pose, or the actuator is stronger or "
             "wired other than configured (re-run the analysis, lower controller.gain_ns_per_m, check the amplifier's "
             "leads)";
    case Trip::kSensorDriver:
      return "the sensor driver reports a fault";
    case Trip::kActuatorDriver:
      return "the actuator driver could not deliver the command, or the amplifier's supervisory (Modbus) link was lost "
             "while it was needed";
    case Trip::kAmplifierFault:
      return "the amplifier reports a fault (temperature, current, link)";
    case Trip::kAmplifierNotReady:
      return "the amplifier did not become ready within supervision.amplifier_ready_timeout_s after enable";
    case Trip::kSignal:
      return "SIGINT/SIGTERM: shut down through the safe state";
    case Trip::kPoseOutOfMap:
      return "the robot's pose is outside every region of pose_schedule, or unknown (the joint angles lost, not "
             "available or not finite, from the Modbus registers or the DDS joint states): no analysed parameter set "
             "applies there";
    case Trip::kCount:
      break;  // not a trip: the enum's count
  }
  return "?";
}

const char* to_string(ArmRefusal r) {
  switch (r) {
    case ArmRefusal::kNone:
      return "none";
    case ArmRefusal::kNotDisabled:
      return "not disabled (reset the fault or disarm first)";
    case ArmRefusal::kSensorNotLive:
      return "sensor not live (needs supervision.arming_live_cycles fresh valid samples)";
    case ArmRefusal::kActuatorPath:
      return "actuator path not healthy (driver or amplifier fault)";
    case ArmRefusal::kAnalysisUnstable:
      return "the analysis does not find the loop stable at this gain with margin";
    case ArmRefusal::kPoseUnknown:
      return "the robot's pose is not known to be in a region of pose_schedule, or that region's set is still being "
             "handed over";
  }
  return "?";
}

const char* to_string(EventKind k) {
  switch (k) {
    case EventKind::kTrip:
      return "trip";
    case EventKind::kRecovered:
      return "recovered";
    case EventKind::kLatched:
      return "latched";
    case EventKind::kProbe:
      return "derate_probe";
    case EventKind::kProcessGrowth:
      return "process_growth";
    case EventKind::kGainFedGrowth:
      return "gain_fed_growth";
    case EventKind::kSaturationDerate:
      return "saturation_derate";
    case EventKind::kRestored:
      return "restored_full_gain";
  }
  return "?";
}

const char* to_string(CommandKind k) {
  switch (k) {
    case CommandKind::kNone:
      return "none";
    case CommandKind::kArm:
      return "arm";
    case CommandKind::kDisarm:
      return "disarm";
    case CommandKind::kResetFault:
      return "reset_fault";
    case CommandKind::kSetGain:
      return "set_gain";
    case CommandKind::kSelectParams:
      return "select_params";
    case CommandKind::kSetSpindle:
      return "set_spindle";
    case CommandKind::kSetPoseRegion:
      return "set_pose_region";
    case CommandKind::kStartExcitation:
      return "start_excitation";
  }
  return "?";
}

}  // namespace robodamp::rt
