// Riding through and recovering from transient faults (issue 28): a stale sensor shorter than the trip
// drives nothing and costs no trip; a transient fault of a recoverable class goes to the safe state as
// always, then re-arms once the cool-down is over and the cell has been healthy for healthy_for_s; the
// budget and the probation latch; latched classes never recover; recordings of it replay bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <unistd.h>

#include "rt/recording.hpp"
#include "rt_loop_outcome.hpp"

namespace robodamp::rt {
namespace {

using sim::FaultKind;

// A stale sensor shorter than stale_sensor_cycles (here 50 ms, as across processes): while it lasts the
// controller's part of the command is zero and the controller is fed no acceleration; with the sample
// back the loop damps at once, with no trip and no fade-in. Hammer hits keep the structure moving.
TEST(StaleRideThrough, AStaleSensorShorterThanTheTripDrivesNothingAndCostsNoTrip) {
  config::Config cfg = c2();
  cfg.supervision.stale_sensor_cycles = 250;
  CellOptions o = virtual_clock();
  o.impact_every_s = 0.9;
  const auto clean = run(cfg, 3.5, o);
  o.record_path = ::testing::TempDir() + "/stale_ride_" + std::to_string(::getpid()) + ".rec";
  const auto r = run(
      cfg, 3.5,
      [](Cell& s) {
        s.plant().faults().add({FaultKind::kSensorDropout, 1.85, 0.04});       // 200 ticks, 50 ms after a hit
        s.plant().faults().add({FaultKind::kSensorDropout, 2.20010, 0.0002});  // lone repeats (CAN de-jitter)
        s.plant().faults().add({FaultKind::kSensorDropout, 2.60010, 0.0002});
      },
      o);
  EXPECT_EQ(r.s.trip, "none");
  EXPECT_EQ(r.s.supervisor.recoveries, 0U);
  const std::size_t full = first_state(r, State::kActive) + static_cast<std::size_t>(0.5 * 5000);
  std::uint64_t held = 0;
  std::size_t resumed = 0;
  for (std::size_t i = full; i < r.frames.size(); ++i) {
    const TelemetryFrame& f = r.frames[i];
    if (f.state != static_cast<std::uint8_t>(State::kActive)) {
      EXPECT_GE(f.time_s, 3.49) << "active to the run's end";
      break;
    }
    if (!(f.flags & kFlagFresh)) {
      ++held;
      ASSERT_EQ(f.command_v, 0.0) << "no tick drives the actuator from a stale sample: tick " << f.tick;
    } else if (i > 0 && !(r.frames[i - 1].flags & kFlagFresh) && f.time_s > 1.85 && f.time_s < 1.9) {
      resumed = i;
    }
  }
  EXPECT_EQ(held, 202U);
  EXPECT_EQ(r.s.supervisor.sensor_hold_ticks, held);
  EXPECT_EQ(r.s.supervisor.sensor_holds, 3U);
  EXPECT_EQ(r.s.supervisor.longest_sensor_hold_ticks, 200U);
  EXPECT_NEAR(r.s.availability.sensor_held_s, 202 / 5000.0, 1e-9);
  // Back at once: the first fresh tick drives the controller's command at full gain (no fade).
  ASSERT_GT(resumed, 0U);
  EXPECT_EQ(r.frames[resumed].command_v, r.frames[resumed].controller_v);
  EXPECT_NE(r.frames[resumed].command_v, 0.0);
  // The controller's velocity estimate held rather than integrating a repeated sample: in the 0.1 s after
  // the sample is back the command stays within the same hit's undisturbed command (plus a margin for the
  // decay it missed).
  double peak_v = 0.0, clean_peak_v = 0.0;
  for (std::size_t i = resumed; i < resumed + 500; ++i) {
    peak_v = std::max(peak_v, std::abs(r.frames[i].command_v));
    clean_peak_v = std::max(clean_peak_v, std::abs(clean.frames[i].command_v));
  }
  std::printf("[ stale    ] 40 ms ridden through: peak command %.3f V in the 0.1 s after (undisturbed %.3f V)\n",
              peak_v, clean_peak_v);
  EXPECT_LT(peak_v, 2.0 * clean_peak_v + 0.05);
  expect_nothing_lost(r);
  const ReplayResult res = replay(read_recording(o.record_path));
  EXPECT_EQ(res.mismatches, 0U) << "the ride-through replays bit for bit";
}

TEST(Recovery, ATransientSensorDropoutRecoversAfterTheCoolDownAndTheHealthCheck) {
  CellOptions o = virtual_clock();
  o.record_path = ::testing::TempDir() + "/recovery_" + std::to_string(::getpid()) + ".rec";
  const auto r = run(
      c2(), 6.0,
      [](Cell& s) {
        s.plant().faults().add({FaultKind::kSensorDropout, 1.0, 0.1});
      },
      o);
  // The trip as before: safe within the stale detection and the ramp.
  const std::size_t fault = first_state(r, State::kFault);
  ASSERT_LT(fault, r.frames.size());
  EXPECT_EQ(r.frames[fault].trip, static_cast<std::uint8_t>(Trip::kSensorStale));
  EXPECT_NEAR(r.frames[fault].time_s, 1.0 + 5 / 5000.0, 2 / 5000.0);
  // Back once the sensor has been healthy for healthy_for_s = 2 s (the cool-down, 1 s, ended earlier): the
  // sensor returns at 1.1 s.
  const std::size_t back = first_state_after(r, State::kArming, r.frames[fault].time_s);
  ASSERT_LT(back, r.frames.size());
  EXPECT_NEAR(r.frames[back].time_s, 1.1 + 2.0, 0.002);
  for (std::size_t i = fault; i < back; ++i) {
    ASSERT_EQ(r.frames[i].state, static_cast<std::uint8_t>(State::kFault)) << i;
    if (r.frames[i].time_s > r.frames[fault].time_s + 0.011) {
      EXPECT_EQ(r.frames[i].command_v, 0.0);
    }
  }
  const std::size_t active = first_state_after(r, State::kActive, r.frames[back].time_s);
  ASSERT_LT(active, r.frames.size());
  EXPECT_EQ(r.frames[active].trip, static_cast<std::uint8_t>(Trip::kNone));
  // Through the gain ramp: the command fades in (0.5 s) from zero.
  EXPECT_LT(std::abs(r.frames[active].command_v), 1e-3);
  EXPECT_EQ(r.s.supervisor.recoveries, 1U);
  EXPECT_EQ(r.s.trip, "none") << "ended damping, not latched";
  ASSERT_EQ(r.s.events.size(), 2U);
  EXPECT_EQ(r.s.events[0].kind, EventKind::kTrip);
  EXPECT_EQ(r.s.events[1].kind, EventKind::kRecovered);
  EXPECT_EQ(r.s.events[1].trip, Trip::kSensorStale);
  EXPECT_NEAR(r.s.events[1].time_s, r.frames[back].time_s, 2 / 5000.0);
  expect_nothing_lost(r);
  const ReplayResult res = replay(read_recording(o.record_path));
  EXPECT_EQ(res.mismatches, 0U) << "the recovery replays bit for bit";
  EXPECT_EQ(res.final_state, r.s.final_state);
}

config::Config with_recovery(int max_recoveries, double probation_s) {
  config::Config c = c2();
  c.supervision.recovery.max_recoveries = max_recoveries;
  c.supervision.recovery.probation_s = probation_s;
  return c;
}

TEST(Recovery, TheBudgetLatchesTheThirdFaultAndTheProbationARelapse) {
  // Three dropouts 4 s apart with a budget of 2: two recoveries, then latched.
  const auto budget = run(with_recovery(2, 0.5), 14.0, [](Cell& s) {
    for (const double t : {1.0, 5.0, 9.0}) s.plant().faults().add({FaultKind::kSensorDropout, t, 0.1});
  });
  EXPECT_EQ(budget.s.supervisor.trips[static_cast<std::size_t>(Trip::kSensorStale)], 3U);
  EXPECT_EQ(budget.s.supervisor.recoveries, 2U);
  EXPECT_EQ(budget.s.supervisor.budget_latches, 1U);
  EXPECT_EQ(budget.s.trip, "sensor_stale");
  EXPECT_EQ(budget.s.final_state, "fault");
  // A relapse 1 s after a recovery, within its 10 s probation: latched at once.
  const auto probation = run(with_recovery(3, 10.0), 8.0, [](Cell& s) {
    s.plant().faults().add({FaultKind::kSensorDropout, 1.0, 0.1});
    s.plant().faults().add({FaultKind::kSensorDropout, 4.5, 0.1});
  });
  EXPECT_EQ(probation.s.supervisor.recoveries, 1U);
  EXPECT_EQ(probation.s.supervisor.probation_latches, 1U);
  EXPECT_EQ(probation.s.trip, "sensor_stale");
  EXPECT_EQ(first_state_after(probation, State::kArming, 4.6), probation.frames.size()) << "no second recovery";
}

TEST(Recovery, LatchedClassesAnEmptyListAndAnOperatorsDisarmNeverRecover) {
  // An amplifier fault may be the damper's doing: latched although it clears after 0.1 s.
  const auto amp = run(c2(), 6.0, [](Cell& s) { s.plant().faults().add({FaultKind::kAmplifierFault, 1.0, 0.1}); });
  EXPECT_EQ(amp.s.trip, "amplifier_fault");
  EXPECT_EQ(amp.s.supervisor.recoveries, 0U);
  EXPECT_EQ(first_state_after(amp, State::kArming, 1.01), amp.frames.size());
  // recoverable: [] latches every trip, as before recovery existed.
  config::Config none = c2();
  none.supervision.recovery.recoverable.clear();
  const auto off = run(none, 6.0, [](Cell& s) { s.plant().faults().add({FaultKind::kSensorDropout, 1.0, 0.1}); });
  EXPECT_EQ(off.s.trip, "sensor_stale");
  EXPECT_EQ(off.s.supervisor.recoveries, 0U);
  // An operator's disarm during the fault: it stays off.
  const auto disarmed = run(c2(), 6.0, [](Cell& s) {
    s.plant().faults().add({FaultKind::kSensorDropout, 1.0, 0.1});
    s.schedule(static_cast<std::uint64_t>(1.5 * 5000), {CommandKind::kDisarm, 0.0});
  });
  EXPECT_EQ(disarmed.s.trip, "sensor_stale");
  EXPECT_EQ(disarmed.s.supervisor.recoveries, 0U);
}

TEST(Recovery, AnOverrunBurstOnTheWallClockRecovers) {
  // A 0.2 s stretch of 0.3 ms stalls (the loop cannot keep 5 kHz) on the real clock: overruns trip, the
  // loop runs on time again, and the damper is back within cool-down + health check + arming.
  CellOptions o;
  o.keep_frames = true;
  config::Config cfg = c2();
  cfg.supervision.recovery.cool_down_s = 0.3;
  cfg.supervision.recovery.healthy_for_s = 0.5;
  const auto r = run(
      cfg, 4.0,
      [](Cell& s) {
        s.plant().faults().add({FaultKind::kDriverStall, 1.0, 0.2, 3e-4});
      },
      o);
  EXPECT_GE(r.s.supervisor.trips[static_cast<std::size_t>(Trip::kOverruns)], 1U);
  EXPECT_GE(r.s.supervisor.recoveries, 1U) << "a loaded machine may stall again, but it recovers at least once";
  EXPECT_LT(first_state_after(r, State::kActive, 1.2), r.frames.size());
}

}  // namespace
}  // namespace robodamp::rt
