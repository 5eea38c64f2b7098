// What a cell's run did: loop timing, supervisor counters, the arming outcome, the devices' counters,
// trip timing. `robodamp run` prints it (apps/run_command.cpp) as text and JSON.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dds/bridge.hpp"
#include "drivers/can_driver.hpp"
#include "drivers/modbus_client.hpp"
#include "runtime/joint_state_pose.hpp"
#include "runtime/path_ahead.hpp"
#include "rt/loop.hpp"
#include "rt/realtime.hpp"
#include "rt/supervisor.hpp"
#include "runtime/arming_policy.hpp"
#include "runtime/speed_advisor.hpp"
#include "rt/availability.hpp"

namespace robodamp::runtime {

// When the run lost its sensor and went safe (from the telemetry frames; loop time since the start).
// The latest trip: one that recovered is replaced by the next, so that with the run's `trip` (the one latched at
// the end) the timing is that trip's.
struct TripTiming {
  double last_fresh_s{-1.0};  // the last fresh sensor sample before the trip
  double trip_s{-1.0};        // the first tick with the trip latched
  double safe_s{-1.0};        // the first tick after it with zero command and the amplifier enable off
  // Ticks the loop ran from the last fresh sample to safe: what the supervisor bounds (stale_sensor_cycles
  // + the trip ramp); in time it is longer by any ticks a loaded machine made the loop skip.
  std::int64_t ticks_to_safe{-1};
};

struct ArmingReport {
  ArmingOutcome outcome{ArmingOutcome::kWaiting};  // kWaiting at the end: the run ended before it armed
  std::uint32_t attempts{0};
  rt::ArmRefusal last_refusal{rt::ArmRefusal::kNone};
  double deadline_s{0.0};
  bool enabled{false};  // false: nobody armed automatically (CellOptions::arm_at_start)
};

struct RunSummary {
  std::string config;
  std::string clock;
  double rate_hz{0.0};
  double duration_s{0.0};
  rt::LoopStats loop;
  rt::SupervisorCounters supervisor;
  std::vector<rt::SupervisorEvent> events;  // trips, recoveries and latches with their times (the first 64)
  std::uint64_t events_total{0};
  std::string final_state, trip, trip_description;
  std::size_t active_parameter_set{0};  // at the end (pose_schedule: the region's index)
  ArmingReport arming;
  double max_stable_gain_ns_per_m{0.0};
  bool analysis_stable{false};
  rt::RealtimeStatus realtime;
  std::uint64_t telemetry_frames{0};
  std::uint64_t recorded_frames{0}, record_errors{0};
  std::string backend;  // "simulated plant" or the CAN transport and Modbus endpoints
  std::optional<drivers::CanCounters> can;
  std::optional<drivers::ModbusCounters> modbus;
  std::optional<dds::BridgeCounters> dds;
  std::optional<JointStateCounters> joint_states;  // dds.joint_states
  std::optional<PathAheadCounters> path_ahead;     // dds.path_ahead
  TripTiming trip_timing;
  rt::Availability availability;  // the share of the asked time at full gain; every trip's safe and re-arm times
  std::string record_path;
  double sensor_rms_mps2{0.0};  // control accelerometer over the run
  double peak_command_v{0.0};
  double spindle_rpm{0.0};      // the speed the controller's notches follow at the end (0: stopped or parked)
  double notch_centre_hz{0.0};  // the harmonic notches' fundamental at the end
  // controller.speed_schedule at the end: the bands, the band of the spindle's speed (none: outside every
  // band), and the K asked for there. The hand-overs are in the supervisor's counters.
  std::size_t speed_bands{0};
  std::optional<std::size_t> speed_band;
  double gain_ns_per_m{0.0};  // K asked for at the end (the schedule's, a request's or the configured)
  std::optional<dds::MachiningSample> machining;  // spindle.job: speed, depth, limits, indicator at the end
  std::optional<AdviceRecord> advice;             // spindle.job: the latest spindle-speed advice, if one was asked for
  std::vector<milling::LiveLimitsRecord> limits_trail;  // spindle.job with pose_schedule: the limits at each pose met

  // The arming policy gave up, or the run ended before the loop was ever active while arming was wanted.
  [[nodiscard]] bool never_armed() const {
    return arming.enabled && arming.outcome != ArmingOutcome::kArmed && arming.outcome != ArmingOutcome::kCancelled &&
           arming.outcome != ArmingOutcome::kFaulted;
  }
};

}  // namespace robodamp::runtime
