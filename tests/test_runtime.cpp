// The runtime layer: the lifecycle's transitions, the arming policy on its own and in a running cell
// (the simulated backend retries, gives up at the deadline and says why), a cell torn down on every
// path, device failures reported as statuses, and parameter requests with random values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "cell_util.hpp"
#include "runtime/arming_policy.hpp"
#include "runtime/components.hpp"
#include "rt/availability.hpp"
#include "runtime/lifecycle.hpp"
#include "runtime/parameter_requests.hpp"
#include "runtime/path_ahead.hpp"
#include "test_util.hpp"

namespace robodamp::runtime {
namespace {

using rt::ArmRefusal;
using rt::CommandKind;
using rt::State;

config::Config c2() { return config::load_config_file(test::preset("horizontal_c2")); }

// --- lifecycle ---------------------------------------------------------------------------------------

class FakeDevice final : public Component {
 public:
  FakeDevice() : Component("fake device") {}
  int fail_configure{0};  // the first N configures fail
  bool throw_on_activate{false};
  int deactivations{0};

 private:
  Status on_configure() override {
    if (fail_configure > 0) return --fail_configure, Status{StatusKind::kDeviceError, "bus not there"};
    return {};
  }
  Status on_activate() override {
    if (throw_on_activate) throw std::runtime_error("port busy");
    return {};
  }
  Status on_deactivate() override {
    ++deactivations;
    return {};
  }
};

// The robot program's trajectory (dds.path_ahead): the schedule's joints found by name in any order and turned to
// degrees; a timed point ahead until it is due, an untimed one for hold_s; a trajectory that lacks a joint, or
// has a point of the wrong length or not finite, refused whole (the last path kept).
TEST(PathAhead, TheProgramsNextPosesByNameUntilTheyAreDue) {
  config::PathAheadConfig cfg;
  cfg.hold_s = 3.0;
  PathAhead ahead(cfg, {"shoulder", "elbow", "wrist"});
  const auto t0 = PathAhead::Clock::now();
  const auto at = [&](double s) {
    return t0 + std::chrono::duration_cast<PathAhead::Clock::duration>(std::chrono::duration<double>(s));
  };
  const double r = M_PI / 180.0;
  const std::vector<std::string> names{"wrist", "gripper", "elbow", "shoulder"};
  ahead.on_message(names,
                   {{{90 * r, 0.0, 20 * r, -100 * r}, 1.0},
                    {{91 * r, 0.0, 60 * r, -100 * r}, 2.5},
                    {{92 * r, 0.0, 100 * r, -100 * r}, 0.0}},
                   t0);
  auto near = [](const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (std::abs(a[i] - b[i]) > 1e-9) return false;
    return true;
  };
  auto poses = ahead.poses_deg(at(0.5));
  ASSERT_EQ(poses.size(), 3U);
  EXPECT_TRUE(near(poses[0], {-100.0, 20.0, 90.0}));
  EXPECT_TRUE(near(poses[2], {-100.0, 100.0, 92.0}));
  poses = ahead.poses_deg(at(1.5));  // the first is due
  ASSERT_EQ(poses.size(), 2U);
  EXPECT_TRUE(near(poses[0], {-100.0, 60.0, 91.0}));
  EXPECT_EQ(ahead.poses_deg(at(2.8)).size(), 1U);  // the untimed one, held for 3 s
  EXPECT_TRUE(ahead.poses_deg(at(3.2)).empty());
  // Refused whole, the last path kept: no elbow; a short point; a position not finite.
  ahead.on_message({"wrist", "shoulder"}, {{{0.0, 0.0}, 1.0}}, t0);
  ahead.on_message(names, {{{0.0, 0.0, 0.0}, 1.0}}, t0);
  ahead.on_message(names, {{{0.0, 0.0, std::nan(""), 0.0}, 1.0}}, t0);
  ahead.on_message(names, {{{0.0, 0.0, 0.0, 0.0}, -1.0}}, t0);
  EXPECT_EQ(ahead.poses_deg(at(0.5)).size(), 3U);
  EXPECT_EQ(ahead.counters().messages, 5U);
  EXPECT_EQ(ahead.counters().refused, 4U);
  // A new trajectory replaces the path; an empty one clears it.
  ahead.on_message(names, {{{0.0, 0.0, 0.0, 0.0}, 1.0}}, t0);
  EXPECT_EQ(ahead.poses_deg(at(0.5)).size(), 1U);
  ahead.on_message(names, {}, t0);
  EXPECT_TRUE(ahead.poses_deg(at(0.5)).empty());
}

TEST(Lifecycle, TransitionsFollowTheStatesAndRefuseTheWrongOnes) {
  FakeDevice d;
  EXPECT_EQ(d.activate().kind, StatusKind::kWrongState);
  EXPECT_EQ(d.state(), LifecycleState::kUnconfigured);
  d.fail_configure = 1;
  const Status failed = d.configure();
  EXPECT_EQ(failed.kind, StatusKind::kDeviceError);
  EXPECT_EQ(d.state(), LifecycleState::kUnconfigured) << "a failed transition stays where it was";
  ASSERT_TRUE(d.configure().ok());
  EXPECT_EQ(d.state(), LifecycleState::kInactive);
  EXPECT_EQ(d.configure().kind, StatusKind::kWrongState);
  d.throw_on_activate = true;
  const Status thrown = d.activate();
  EXPECT_EQ(thrown.kind, StatusKind::kDeviceError);
  EXPECT_NE(thrown.message.find("fake device: port busy"), std::string::npos) << thrown.message;
  EXPECT_EQ(d.state(), LifecycleState::kInactive);
  d.throw_on_activate = false;
  ASSERT_TRUE(d.activate().ok());
  EXPECT_EQ(d.cleanup().kind, StatusKind::kWrongState) << "clean up only when inactive";
  ASSERT_TRUE(d.deactivate().ok());
  EXPECT_EQ(d.deactivations, 1);
  ASSERT_TRUE(d.cleanup().ok());
  EXPECT_EQ(d.state(), LifecycleState::kUnconfigured);
}

// --- the arming policy alone ----------------------------------------------------------------------------

TEST(ArmingPolicy, ArmsAtTheFirstLiveTickAndRetriesUntilActive) {
  ArmingPolicy p({51, 100, 1000});
  for (std::uint64_t t = 0; t < 51; ++t)
    EXPECT_EQ(p.on_tick(t, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kNone);
  EXPECT_EQ(p.on_tick(51, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kArm);
  // Refused: the supervisor stays disabled; the next attempt comes retry_ticks later.
  for (std::uint64_t t = 52; t < 151; ++t)
    EXPECT_EQ(p.on_tick(t, State::kDisabled, ArmRefusal::kSensorNotLive).command.kind, CommandKind::kNone) << t;
  EXPECT_EQ(p.on_tick(151, State::kDisabled, ArmRefusal::kSensorNotLive).command.kind, CommandKind::kArm);
  EXPECT_EQ(p.attempts(), 2U);
  EXPECT_EQ(p.last_refusal(), ArmRefusal::kSensorNotLive);
  EXPECT_EQ(p.on_tick(152, State::kArming, ArmRefusal::kNone).command.kind, CommandKind::kNone);
  EXPECT_EQ(p.on_tick(153, State::kActive, ArmRefusal::kNone).command.kind, CommandKind::kNone);
  EXPECT_EQ(p.outcome(), ArmingOutcome::kArmed);
  // The end of the run disarms: never re-armed.
  EXPECT_EQ(p.on_tick(5000, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kNone);
}

TEST(ArmingPolicy, GivesUpAtTheDeadlineAndEndsTheRun) {
  ArmingPolicy p({51, 100, 400});
  int arms = 0;
  rt::PolicyDecision d;
  std::uint64_t t = 0;
  for (; t < 1000; ++t) {
    d = p.on_tick(t, State::kDisabled, ArmRefusal::kAnalysisUnstable);
    if (d.command.kind == CommandKind::kArm) ++arms;
    if (d.end_run) break;
  }
  EXPECT_EQ(t, 400U);
  EXPECT_EQ(arms, 4) << "ticks 51, 151, 251, 351";
  EXPECT_EQ(p.outcome(), ArmingOutcome::kGaveUp);
  EXPECT_EQ(p.last_refusal(), ArmRefusal::kAnalysisUnstable);
  EXPECT_FALSE(p.on_tick(401, State::kDisabled, ArmRefusal::kAnalysisUnstable).end_run) << "once";
}

TEST(ArmingPolicy, StopsAtATripAndWhenAnOperatorTakesOver) {
  ArmingPolicy tripped({1, 10, 100});
  EXPECT_EQ(tripped.on_tick(1, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kArm);
  EXPECT_EQ(tripped.on_tick(2, State::kFault, ArmRefusal::kNone).command.kind, CommandKind::kNone);
  EXPECT_EQ(tripped.outcome(), ArmingOutcome::kFaulted);
  EXPECT_EQ(tripped.on_tick(50, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kNone)
      << "a reset is the operator's, and so is the arm after it";
  ArmingPolicy cancelled({1, 10, 100});
  cancelled.cancel();
  EXPECT_EQ(cancelled.on_tick(1, State::kDisabled, ArmRefusal::kNone).command.kind, CommandKind::kNone);
  EXPECT_EQ(cancelled.outcome(), ArmingOutcome::kCancelled);
}

TEST(ArmingPolicy, ScheduleComesFromTheSupervisionSection) {
  config::SupervisionConfig s;
  s.arming_live_cycles = 50;
  s.arm_retry_s = 0.5;
  s.arm_deadline_s = 10.0;
  const ArmingSchedule a = ArmingSchedule::from(s, 5000.0);
  EXPECT_EQ(a.first_tick, 51U);
  EXPECT_EQ(a.retry_ticks, 2500U);
  EXPECT_EQ(a.deadline_tick, 50051U);
}

// --- the arming policy in a running cell ------------------------------------------------------------------

CellOptions virtual_clock() {
  CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.keep_frames = true;
  return o;
}

// Before the runtime layer, the simulated backend armed once at a fixed tick: a refused attempt left the
// damper off for the whole run. Now the first attempt is refused (the sensor is dropped out for 0.3 s)
// and a retry arms it.
TEST(CellArming, ARefusedFirstAttemptIsRetriedOnTheSimulatedBackend) {
  Cell cell(c2(), virtual_clock());
  test::configure(cell);
  cell.plant().faults().add({sim::FaultKind::kSensorDropout, 0.0, 0.3});
  ASSERT_TRUE(cell.run(3.0).ok());
  const RunSummary& s = cell.summary();
  EXPECT_EQ(s.arming.outcome, ArmingOutcome::kArmed);
  EXPECT_EQ(s.arming.attempts, 2U) << "refused at 10.2 ms, armed at 510 ms";
  EXPECT_EQ(s.arming.last_refusal, ArmRefusal::kSensorNotLive);
  EXPECT_EQ(s.supervisor.arm_refused, 1U);
  EXPECT_EQ(s.trip, "none");
  EXPECT_FALSE(s.never_armed());
  EXPECT_GT(s.peak_command_v, 0.0) << "the damper ran";
  bool active = false;
  for (const auto& f : cell.frames()) active = active || f.state == static_cast<std::uint8_t>(State::kActive);
  EXPECT_TRUE(active);
}

TEST(CellArming, GivesUpAtTheDeadlineNamingTheRefusalAndEndsTheRunEarly) {
  auto cfg = c2();
  cfg.controller.gain_ns_per_m = 4700.0;  // stable, but above max_gain_fraction 0.9 x K_max 4805
  cfg.supervision.arm_deadline_s = 1.2;
  Cell cell(cfg, virtual_clock());
  test::configure(cell);
  ASSERT_TRUE(cell.run(30.0).ok());
  const RunSummary& s = cell.summary();
  EXPECT_EQ(s.arming.outcome, ArmingOutcome::kGaveUp);
  EXPECT_EQ(s.arming.attempts, 3U) << "at 10.2 ms, 510 ms and 1010 ms";
  EXPECT_EQ(s.arming.last_refusal, ArmRefusal::kAnalysisUnstable);
  EXPECT_TRUE(s.never_armed());
  EXPECT_LT(s.loop.ticks_run, 5000U * 3) << "ended at the deadline, not after 30 s";
  EXPECT_EQ(s.final_state, "disabled");
}

TEST(CellArming, ArmingTheSameWayOnEveryRunOfTheVirtualClock) {
  auto once = [] {
    Cell cell(c2(), virtual_clock());
    test::configure(cell);
    cell.plant().faults().add({sim::FaultKind::kSensorDropout, 0.0, 0.7});
    (void)cell.run(2.0);
    return cell.frames();
  };
  const auto a = once(), b = once();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].command_kind, b[i].command_kind) << i;
    ASSERT_EQ(a[i].command_v, b[i].command_v) << i;
  }
}

// --- the cell's lifecycle --------------------------------------------------------------------------------

CellOptions wall_clock_no_rt() {
  CellOptions o;
  o.realtime_setup = false;  // the loop's real-time set-up is the run command's; tests share the machine
  return o;
}

TEST(CellLifecycle, TransitionsInOrderAndDeactivateEndsARunEarly) {
  Cell cell(c2(), wall_clock_no_rt());
  EXPECT_EQ(cell.activate(1.0).kind, StatusKind::kWrongState) << "configure first";
  test::configure(cell);
  EXPECT_EQ(cell.state(), LifecycleState::kInactive);
  ASSERT_TRUE(cell.activate(3600.0).ok());  // wall clock, an hour
  EXPECT_EQ(cell.state(), LifecycleState::kActive);
  EXPECT_EQ(cell.cleanup().kind, StatusKind::kWrongState);
  ASSERT_TRUE(test::eventually([&] { return cell.arming().outcome() == ArmingOutcome::kArmed; }, 60.0));
  ASSERT_TRUE(cell.deactivate().ok());
  EXPECT_EQ(cell.state(), LifecycleState::kInactive);
  EXPECT_EQ(cell.summary().final_state, "disabled") << "through the disarm fade to the safe state";
  EXPECT_LT(cell.summary().loop.elapsed_s, 3600.0);
  EXPECT_EQ(cell.activate(1.0).kind, StatusKind::kWrongState) << "a configuration runs once";
  ASSERT_TRUE(cell.cleanup().ok());
  EXPECT_EQ(cell.state(), LifecycleState::kUnconfigured);
}

// The process's threads (/proc/self/task): ctest runs each test in a process of its own.
std::size_t thread_count() {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/task")) ++n;
  return n;
}

TEST(CellLifecycle, DestroyingAnActiveCellStopsAndJoinsEverything) {
  // A thread started and joined first: a runtime that starts a helper thread of its own at the process's first
  // thread (ThreadSanitizer's background thread) has it before the count, so the count is the cell's alone.
  std::thread([] {}).join();
  const std::size_t before = thread_count();
  auto cell = std::make_unique<Cell>(c2(), wall_clock_no_rt());
  test::configure(*cell);
  ASSERT_TRUE(cell->activate(3600.0).ok());
  EXPECT_GT(thread_count(), before) << "the active cell runs its loop and workers on threads of its own";
  cell.reset();  // a test that returns early does this: no std::terminate, no thread left
  EXPECT_EQ(thread_count(), before) << "every thread the cell started was joined by its destructor";
}

TEST(CellLifecycle, ADeviceThatCannotBeOpenedIsADeviceErrorAndNothingIsLeftOpen) {
  auto cfg = config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_horizontal_c2.yaml");
  cfg.can->interface = "unix:/nonexistent/robodamp.sock";
  CellOptions o;
  o.connect_timeout_s = 0.2;
  Cell cell(cfg, o);
  const Status s = cell.configure();
  EXPECT_EQ(s.kind, StatusKind::kDeviceError);
  EXPECT_NE(s.message.find("/nonexistent/robodamp.sock"), std::string::npos) << s.message;
  EXPECT_EQ(cell.state(), LifecycleState::kUnconfigured);
}

TEST(CellLifecycle, HalfAHardwareConfigurationIsAConfigError) {
  auto cfg = config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_horizontal_c2.yaml");
  cfg.modbus.reset();
  Cell cell(cfg);
  const Status s = cell.configure();
  EXPECT_EQ(s.kind, StatusKind::kConfigError);
  EXPECT_NE(s.message.find("modbus"), std::string::npos) << s.message;
}

// One rollback path: a configure that fails at its last step (a spindle.job that does not parse, after the
// devices, the loop and the parameter sets are built) leaves the cell unconfigured with nothing left
// built, so a second configure fails the same way instead of finding the first one's devices.
TEST(CellLifecycle, AFailedConfigureLeavesTheCellUnconfiguredAndFailsAgainTheSameWay) {
  auto cfg = config::load_config_file(robodamp::test::preset("horizontal_c2"));
  const std::string bad = ::testing::TempDir() + "robodamp_bad_job.yaml";
  { std::ofstream(bad) << "tool: [not a job\n"; }
  cfg.spindle.job = cfg.spindle.job_resolved = bad;
  Cell cell(cfg, virtual_clock());
  for (int attempt = 0; attempt < 2; ++attempt) {
    const Status s = cell.configure();
    EXPECT_EQ(s.kind, StatusKind::kConfigError) << attempt;
    EXPECT_NE(s.message.find("spindle.job"), std::string::npos) << s.message;
    EXPECT_EQ(cell.state(), LifecycleState::kUnconfigured);
  }
  std::remove(bad.c_str());
}

// --- parameter requests with random values ----------------------------------------------------------------

// The machining monitor's advisor publishes advice and reads the robot's depth through the Modbus
// component from the cell's configure to its cleanup, which is longer than the component's client lives
// (a run that ended under load crashed where the client had gone first): before its configure and after
// its cleanup the depth is unknown and an advice goes nowhere, without a crash.
TEST(CellComponents, TheModbusClientsAdviceAndDepthAreSafeOutsideItsLife) {
  config::ModbusConfig cfg;
  cfg.amplifier_link.host = "127.0.0.1";
  cfg.amplifier_link.port = 1;  // nothing listens: never started here
  runtime::ModbusComponent m(cfg, config::Mounting::kHorizontal, {}, 0.1);
  EXPECT_TRUE(std::isnan(m.robot_depth_mm()));
  m.publish_advice(1, true, 666.7, 2.0);
  ASSERT_TRUE(m.configure().ok());
  EXPECT_TRUE(std::isnan(m.robot_depth_mm()));  // no poll yet
  m.publish_advice(2, false, 0.0, 0.0);
  ASSERT_TRUE(m.cleanup().ok());
  EXPECT_TRUE(std::isnan(m.robot_depth_mm()));
  m.publish_advice(3, true, 700.0, 1.5);
}

TEST(ParameterRequests, RandomValuesAreAcceptedOnlyInRangeAndAlwaysSayWhy) {
  auto cfg = c2();
  Cell cell(cfg, virtual_clock());
  test::configure(cell);
  cell.add_parameter_set(config::load_config_file(test::preset("horizontal_c1")));
  const rt::Supervisor& sup = cell.supervisor();
  const double limit = sup.gain_limit_ns_per_m();
  std::mt19937_64 rng(13);
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             -0.0,
                             0.0,
                             1.0,
                             2.0,
                             -1.0,
                             1e308,
                             -1e308,
                             std::numeric_limits<double>::denorm_min(),
                             limit,
                             std::nextafter(limit, 1e9),
                             0.5,
                             1.5};
  std::uniform_real_distribution<double> wide(-1e6, 1e6);
  std::uniform_int_distribution<int> pick(0, 4), special(0, std::size(specials) - 1), coin(0, 1);
  int accepted = 0;
  for (int i = 0; i < 10000; ++i) {
    const auto kind = static_cast<dds::RequestKind>(pick(rng));
    const double v = coin(rng) ? specials[special(rng)] : wide(rng);
    const CheckedRequest r = check_request(sup, cfg, kind, v);
    EXPECT_FALSE(r.decision.reason.empty());
    if (!r.decision.accepted) {
      EXPECT_EQ(r.command.kind, CommandKind::kNone);
      continue;
    }
    ++accepted;
    ASSERT_TRUE(std::isfinite(v)) << r.decision.reason;
    switch (kind) {
      case dds::RequestKind::kSetGain:
        EXPECT_GE(v, 0.0);
        EXPECT_LE(v, limit);
        EXPECT_EQ(r.command.kind, CommandKind::kSetGain);
        break;
      case dds::RequestKind::kSelectParameterSet:
        EXPECT_TRUE(v == 0.0 || v == 1.0) << v;
        EXPECT_EQ(r.command.kind, CommandKind::kSelectParams);
        break;
      case dds::RequestKind::kEnable:
        EXPECT_TRUE(v == 0.0 || v == 1.0) << v;
        break;
      case dds::RequestKind::kSetSpindleRpm:
        EXPECT_GE(v, 0.0);
        EXPECT_LE(v, cfg.spindle.rpm_max);
        EXPECT_EQ(r.command.kind, CommandKind::kSetSpindle);
        break;
      case dds::RequestKind::kResetFault:  // accepted only while the loop is in fault
        EXPECT_EQ(sup.observed_state(), rt::State::kFault);
        EXPECT_EQ(r.command.kind, CommandKind::kResetFault);
        break;
    }
  }
  EXPECT_GT(accepted, 100);
  std::printf("[ requests ] 10000 random parameter requests, %d accepted\n", accepted);
}

// The availability meter on a scripted run at 1 kHz with a 0.1 s gain ramp: start-up (not asked), full gain
// from 0.2 s, a trip at 2 s (safe 10 ms later, re-armed at 5 s, full gain at 5.1 s), 20 missed ticks at
// 7 s, 4 stale samples ridden through at 8 s (not damping), the run's own stop at 9 s (not asked).
TEST(Availability, CountsTheAskedTimeAtFullGainAndEachTripsSafeAndReArmTimes) {
  rt::AvailabilityMeter m(1000.0, 0.1);
  auto frame = [&](std::uint64_t tick, rt::State st, rt::Trip trip, double command_v, bool enable) {
    rt::TelemetryFrame f;
    f.tick = tick;
    f.time_s = static_cast<double>(tick) * 1e-3;
    f.state = static_cast<std::uint8_t>(st);
    f.trip = static_cast<std::uint8_t>(trip);
    f.command_v = command_v;
    const bool stale = tick >= 8000 && tick < 8004;
    f.flags = static_cast<std::uint16_t>((enable ? rt::kFlagAmplifierEnable : 0) | (stale ? 0 : rt::kFlagFresh));
    m.on_frame(f);
  };
  for (std::uint64_t k = 0; k <= 10000; ++k) {
    if (k >= 7000 && k < 7020) continue;  // missed: no frames
    if (k < 100)
      frame(k, rt::State::kArming, rt::Trip::kNone, 0.0, true);
    else if (k < 2000)
      frame(k, rt::State::kActive, rt::Trip::kNone, 0.1, true);
    else if (k < 2010)
      frame(k, rt::State::kStopping, rt::Trip::kSensorStale, 0.05, true);
    else if (k < 4900)
      frame(k, rt::State::kFault, rt::Trip::kSensorStale, 0.0, false);
    else if (k < 5000)
      frame(k, rt::State::kArming, rt::Trip::kNone, 0.0, true);
    else if (k < 9000)
      frame(k, rt::State::kActive, rt::Trip::kNone, 0.1, true);
    else
      frame(k, rt::State::kStopping, rt::Trip::kNone, 0.0, true);
  }
  const rt::Availability& a = m.result();
  EXPECT_NEAR(a.first_full_gain_s, 0.2, 1e-9);
  EXPECT_NEAR(a.asked_s, 9.0 - 0.2, 1.5e-3);                           // 0.2 .. 9.0 s
  EXPECT_NEAR(a.active_s, (2.0 - 0.2) + (9.0 - 5.1) - 0.004, 1.5e-3);  // less the trip and the stale ticks
  EXPECT_NEAR(a.missed_while_active_s, 0.020, 1e-9);                   // of it, the 20 missed ticks
  EXPECT_NEAR(a.sensor_held_s, 0.004, 1e-9);
  EXPECT_NEAR(a.share(), a.active_s / a.asked_s, 1e-12);
  ASSERT_EQ(a.trips_total, 1u);
  ASSERT_EQ(a.trips.size(), 1u);
  EXPECT_EQ(a.trips[0].trip, "sensor_stale");
  EXPECT_NEAR(a.trips[0].trip_s, 2.0, 1e-9);
  EXPECT_NEAR(a.trips[0].safe_s, 2.010, 1e-9);
  EXPECT_NEAR(a.trips[0].rearmed_s, 5.0, 1e-9);
  EXPECT_NEAR(a.trips[0].full_gain_again_s, 5.1, 1e-9);
}

}  // namespace
}  // namespace robodamp::runtime
