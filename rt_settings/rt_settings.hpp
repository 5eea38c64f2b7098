// The real-time core's settings as plain structs, and its trip classes by name (docs/architecture.md): the
// loop's clock, the real-time thread's start-up, the supervisor's trips, recovery and derating. Nothing
// here knows the configuration file: config/ parses YAML into these structs (config::SupervisionConfig is
// rt::SupervisionLimits), and rt/ reads them, so the real-time core links neither the parser nor yaml-cpp
// (as ros2_control keeps its real-time interfaces free of the parser). Header-only, no dependencies.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace robodamp::rt {

// wall: clock_nanosleep on CLOCK_MONOTONIC (hardware, real-time simulation); virtual: ticks back to back as
// fast as possible, time = tick / rate (bench runs, bit-identical run to run).
enum class ClockKind { kWall, kVirtual };
[[nodiscard]] constexpr const char* to_string(ClockKind clock) {
  return clock == ClockKind::kWall ? "wall" : "virtual";
}

// Why the supervisor went to the safe state. kTripNames is the one table of their names (what logs,
// summaries, recordings, DDS and the configuration's supervision.recovery.recoverable say).
enum class Trip : std::uint8_t {
  kNone,
  kSensorStale,        // no fresh sample for stale_sensor_cycles ticks
  kSampleInvalid,      // non-finite or out-of-range samples for invalid_sample_cycles ticks
  kOverruns,           // overrun_cycles consecutive overruns
  kSaturation,         // more than saturation_duty_max of the window's ticks at a limit
  kInstability,        // the loop signal grew in instability_blocks consecutive blocks
  kSensorDriver,       // the sensor driver reports a fault
  kActuatorDriver,     // the actuator driver could not deliver the command
  kAmplifierFault,     // the amplifier reports a fault
  kAmplifierNotReady,  // enabled but not ready within amplifier_ready_timeout_s
  kSignal,             // SIGINT / SIGTERM: shut down through the safe state
  kPoseOutOfMap,       // pose_schedule: the pose is outside every region, or unknown, or its set was refused
  kCount,              // not a trip: the number of them
};
inline constexpr std::size_t kTripCount = static_cast<std::size_t>(Trip::kCount);
inline constexpr std::array<std::string_view, kTripCount> kTripNames{
    "none",        "sensor_stale",   "sample_invalid",  "overruns",        "saturation",
    "instability", "sensor_driver",  "actuator_driver", "amplifier_fault", "amplifier_not_ready",
    "signal",      "pose_out_of_map"};
static_assert(kTripNames.back() == "pose_out_of_map", "a name for each trip, in the enum's order");

[[nodiscard]] constexpr std::string_view trip_name(Trip t) {
  const auto i = static_cast<std::size_t>(t);
  return i < kTripCount ? kTripNames[i] : std::string_view{"?"};
}
// The trip of that name (kTripNames), or nothing.
[[nodiscard]] constexpr std::optional<Trip> trip_named(std::string_view name) {
  for (std::size_t i = 0; i < kTripCount; ++i)
    if (kTripNames[i] == name) return static_cast<Trip>(i);
  return std::nullopt;
}

// The trip classes that may be recoverable; the others (instability, saturation, amplifier_fault,
// pose_out_of_map, signal) the damper may have caused, or an operator must see.
inline constexpr std::array<Trip, 6> kRecoverableTrips{Trip::kOverruns,       Trip::kSensorStale,
                                                       Trip::kSampleInvalid,  Trip::kSensorDriver,
                                                       Trip::kActuatorDriver, Trip::kAmplifierNotReady};
[[nodiscard]] constexpr bool may_recover(Trip t) {
  for (const Trip r : kRecoverableTrips)
    if (r == t) return true;
  return false;
}

// Start-up of the real-time thread. Each step that is not permitted falls back with a warning.
struct RealtimeSettings {
  int priority{80};                 // SCHED_FIFO 1-99; 0 = stay SCHED_OTHER
  int cpu{-1};                      // CPU affinity; -1 = any
  bool lock_memory{true};           // mlockall(MCL_CURRENT | MCL_FUTURE)
  int stack_prefault_kib{256};      // stack touched before activation
  bool hold_cpu_dma_latency{true};  // /dev/cpu_dma_latency held at 0 us while running
};

// Automatic recovery from a transient fault (docs/runtime.md, "Recovery"): after a trip of a recoverable
// class the safe state as always, then once the cool-down is over and the cell has been healthy for
// healthy_for_s (sensor live, ticks on time, actuator path and amplifier without fault, the active set's
// analysis stable, the pose in a region where scheduled) the supervisor re-arms through the gain ramp.
// At most max_recoveries within window_s; a trip within probation_s of a recovery, or of a class not
// listed, latches until an operator resets it.
struct RecoverySettings {
  // Trip classes that may recover (each of kRecoverableTrips at most once, in the order given); empty:
  // every trip latches.
  std::vector<Trip> recoverable{Trip::kOverruns, Trip::kSensorStale, Trip::kSampleInvalid, Trip::kSensorDriver,
                                Trip::kActuatorDriver};
  double cool_down_s{1.0};
  double healthy_for_s{2.0};
  int max_recoveries{3};
  double window_s{600.0};
  double probation_s{10.0};
};

// Keeping damping through chatter (docs/realtime_loop.md, "Keeping damping when the cut chatters"): with the
// spindle turning, growth and saturation derate the gain instead of tripping, as long as a probe says the gain
// is not what feeds them. With the spindle stopped nothing but the loop can feed a growth: it trips as before.
struct DerateSettings {
  bool enabled{true};
  // Where the instability rule would trip, the gain goes to probe_factor (x K) over probe_ramp_s for probe_blocks
  // instability blocks instead; decaying there (the structure's motion not growing): the gain fed it, ...
  int probe_blocks{4};
  double probe_factor{0.0};
  double hold_factor{0.5};  // ... and the gain is held at this (x K) until quiet (growing on: the process's)
  double probe_ramp_s{0.02};
  double quiet_s{1.0};            // no growth and the saturation duty under a quarter of its limit this long: ...
  double restore_s{2.0};          // ... back to full gain over this ramp
  double saturation_factor{0.5};  // each saturation duty over the limit multiplies the derating by this ...
  double min_factor{0.0625};      // ... down to this; below it the saturation trips as before
};

// The supervisor's trips and ramps (rt/supervisor.hpp).
struct SupervisionLimits {
  int stale_sensor_cycles{5};  // consecutive ticks without a fresh sample: trip
  // While the sample is stale or invalid the controller's part of the command is zero and the controller
  // is fed no acceleration (docs/realtime_loop.md, "Riding through a stale sensor"). Not a configuration
  // key: a recording made before it replays with false (the last valid sample held, as it ran).
  bool zero_command_while_stale{true};
  int invalid_sample_cycles{1};   // consecutive non-finite or out-of-range samples
  double sample_limit_mps2{0.0};  // out of range beyond this; 0 = the sensor's range (sensor.range_g)
  int overrun_cycles{10};         // consecutive overruns (compute past the period or missed ticks) ...
  // ... lasting, in measured time, at least this share of the active set's delay margin (the extra delay
  // the loop tolerates for good, analysis/loop_model.hpp): a stall shorter than that cannot destabilise
  // the loop, so it is ridden through (counted). 0 = overrun_cycles alone.
  double overrun_delay_margin_share{1.0};
  double saturation_window_s{0.5};
  double saturation_duty_max{0.2};        // fraction of the window's ticks at a controller or actuator limit
  double instability_block_s{0.1};        // command RMS per block
  int instability_blocks{8};              // growth in every one of this many consecutive blocks ...
  double instability_growth_factor{1.5};  // ... and by at least this factor overall
  double instability_floor_v{0.02};       // RMS below this is never called unstable
  double trip_ramp_s{0.01};               // a trip ramps the command to zero within this time
  int arming_live_cycles{50};             // fresh, valid samples needed before arming
  // The arming policy (runtime/arming_policy.hpp), the same for every backend: arm once the sensor can
  // be live, retry every arm_retry_s while refused, give up after arm_deadline_s of loop time (the run
  // then ends with the last refusal and a non-zero exit status).
  double arm_retry_s{0.5};
  double arm_deadline_s{10.0};
  double amplifier_ready_timeout_s{0.2};
  double max_gain_fraction{0.9};  // gain requests up to this x the analysed maximum stable K
  RecoverySettings recovery;
  DerateSettings derate;
};

// What the supervisor needs beyond the controller's parameters; a recording stores it.
struct SupervisorSettings {
  SupervisionLimits limits;
  double fs_hz{5000.0};
  double sample_limit_mps2{0.0};  // resolved (never 0)
  double fade_s{0.5};             // activation / disarm fade (controller.gain_ramp_s)
  bool analysis_stable{false};    // the analysis found the configured loop stable
  double max_stable_gain_ns_per_m{0.0};
  double delay_margin_s{0.0};    // the analysis' delay margin at the configured gain (0: none known)
  double command_limit_v{10.0};  // the amplifier's voltage limit: a command with excitation is clamped to it
  // pose_schedule: arming waits for a pose in a region (set_pose_region), the supervisor hands over to
  // each region's set as the pose moves, and a pose out of the map trips (kPoseOutOfMap).
  bool pose_scheduled{false};
};

}  // namespace robodamp::rt
