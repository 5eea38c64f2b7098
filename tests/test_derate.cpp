// Keeping damping when the cut chatters (docs/realtime_loop.md): the real supervisor and controller against the
// trips the derating replaces, on the default job's cut in time (tune::supervised_cut) and on the simulated cell
// (runtime::Cell) with its sensor noise, drive vibration and hammer blows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "rt/recording.hpp"
#include "rt_loop_outcome.hpp"
#include "test_util.hpp"
#include "tune/scheduled_cut.hpp"

namespace robodamp {
namespace {

config::Config fixed_c2() {
  config::Config c = config::load_config_file(test::preset("horizontal_c2"));
  c.controller.speed_schedule.reset();  // C2 at K = 2000 N s/m at every speed: the default preset without its schedule
  return c;
}

config::MillingConfig default_job() {
  return config::load_milling_config(test::source_path("config/milling/active_damping_c2.yaml"));
}

// 10.3 s of cut at any speed (120 revolutions at 699.3 rpm).
tune::ScheduledCut cut_at(const config::Config& cell, double rpm, double depth_mm,
                          const config::Config* plant = nullptr) {
  tune::SupervisedCutOptions o;
  o.revolutions = static_cast<int>(std::lround(120.0 * rpm / 700.0));
  o.plant = plant;
  return tune::supervised_cut(cell, default_job(), {{rpm, depth_mm}}, o);
}

void print(const char* name, const tune::ScheduledCut& r) {
  for (const auto& s : r.segments)
    std::printf(
        "[ derate   ] %s: %.1f rpm %.2f mm: cut %s, %s/%s, derated %.2f s (lowest %.2f), trip %.2f s into the cut, "
        "peak force %.1f N, %llu ticks at a limit\n",
        name, s.rpm, s.depth_mm, milling::to_string(s.verdict.classification), s.state.c_str(), s.trip.c_str(),
        s.derated_s, s.lowest_derate, s.trip_s, s.peak_force_command_n,
        static_cast<unsigned long long>(s.limited_ticks));
  const auto& c = r.counters;
  std::printf(
      "[ derate   ] %s: probes %llu (the process's %llu, fed by the gain %llu), saturation derates %llu, restores "
      "%llu\n",
      name, static_cast<unsigned long long>(c.derate_probes), static_cast<unsigned long long>(c.growth_process),
      static_cast<unsigned long long>(c.growth_gain_fed), static_cast<unsigned long long>(c.saturation_derates),
      static_cast<unsigned long long>(c.derate_restores));
}

// C2 at K = 2000 at 699.3 rpm lowers the default job's limit to 0.782 mm (open loop 1.106 mm). Cuts above it: 0.95 mm
// (the damper's own chatter), 1.3 mm (above the open loop's too) and 1.56 mm (2 x the damped limit). Without
// derating 1.3 and 1.56 mm trip instability (latched: the damper off for the rest of the run); with derating none
// trips and the damper stays armed, at full gain but for the probe that judged the growth the process's.
TEST(Derate, AChatteringCutNeverSwitchesTheDamperOff) {
  config::Config off = fixed_c2();
  off.supervision.derate.enabled = false;
  for (const double depth : {1.3, 1.56}) {
    const auto r = cut_at(off, 700.0, depth);
    print("derating off", r);
    ASSERT_EQ(r.segments.size(), 1U);
    EXPECT_EQ(r.segments[0].trip, "instability") << depth << " mm: the trip the derating replaces";
    EXPECT_FALSE(r.segments[0].verdict.stable) << depth << " mm";
  }
  for (const double depth : {0.95, 1.3, 1.56}) {
    const auto r = cut_at(fixed_c2(), 700.0, depth);
    print("derating on", r);
    ASSERT_EQ(r.segments.size(), 1U);
    const auto& s = r.segments[0];
    EXPECT_EQ(s.trip, "none") << depth << " mm";
    EXPECT_EQ(s.state, "active") << depth << " mm";
    EXPECT_EQ(r.counters.derate_probes, r.counters.growth_process + r.counters.growth_gain_fed) << "every probe judged";
    EXPECT_LE(s.peak_force_command_n, r.force_limit_n + 1e-9);
    if (depth > 1.0) {
      EXPECT_GE(r.counters.growth_process, 1U) << depth << " mm: the growth probed and found the process's";
      EXPECT_LT(s.derated_s, 0.1 * 10.3) << depth << " mm: at full gain but for the probe";
    }
  }
}

// Cuts that drive the actuator into its 36 N force limit, on the scheduled default preset: 4.7 mm at 699.3 rpm
// (2 x the band's 2.35 mm limit), 10 mm there, 20 mm at 1204.8 rpm. Without derating each trips saturation
// within 1.1 s; with it none trips: the saturation is derated (after the cut's entry has rung down, probed
// first: an external force, or held lowered when the gain seemed to feed it), the damper armed throughout.
TEST(Derate, ACutThatSaturatesTheActuatorIsDeratedNotTripped) {
  const config::Config cell = config::load_config_file(test::preset("horizontal_c2"));
  config::Config off = cell;
  off.supervision.derate.enabled = false;
  for (const auto& [rpm, depth] : {std::pair{700.0, 4.7}, std::pair{700.0, 10.0}, std::pair{1200.0, 20.0}}) {
    const auto r_off = cut_at(off, rpm, depth);
    print("derating off", r_off);
    ASSERT_EQ(r_off.segments.size(), 1U);
    EXPECT_EQ(r_off.segments[0].trip, "saturation") << depth << " mm: the trip the derating replaces";
    const auto r = cut_at(cell, rpm, depth);
    print("derating on", r);
    ASSERT_EQ(r.segments.size(), 1U);
    const auto& s = r.segments[0];
    EXPECT_EQ(s.trip, "none") << depth << " mm";
    EXPECT_EQ(s.state, "active") << depth << " mm";
    EXPECT_FALSE(s.verdict.stable) << depth << " mm: a chattering cut";
    EXPECT_GT(s.limited_ticks, 0U) << depth << " mm: the actuator at its limit";
    EXPECT_GE(r.counters.saturation_derates, 1U) << depth << " mm: the saturation derated, not tripped";
    EXPECT_LE(s.peak_force_command_n, r.force_limit_n + 1e-9);
  }
}

// A loop that is unstable on its own inside a band of the scheduled default preset, with the spindle turning:
// the amplifier's leads swapped (plant.actuator_wiring -1) and the actuator 4.88 x stronger than configured
// (1.25 x the band's K_max of 11 874 N s/m) at 699.3 rpm, 3 x stronger at 1204.8 rpm (C2 at 2400: 1.5 x its
// 4805). The band's gain was verified not to lower the cut's limit, so a growth it feeds trips at once: each
// trips instability within 0.6 s of the time the supervisor without derating trips (the probe's cost; the
// times in docs/realtime_loop.md), whether the robot cuts air (a 1 um pass) or 0.3 mm. Swapped leads also trip
// while a chattering cut runs (3 and 5 mm, the actuator saturated: the saturation is probed, the gain held
// lowered, and the growth it still feeds at the same speed trips).
TEST(Derate, ALoopUnstableOnItsOwnTripsInAScheduledBandEvenWhileTheCutChatters) {
  const config::Config cell = config::load_config_file(test::preset("horizontal_c2"));
  config::Config off = cell;
  off.supervision.derate.enabled = false;
  config::Config swapped = cell, k125 = cell, x3 = cell;
  swapped.plant.actuator_wiring = -1;
  k125.actuator.constant_n_per_v *= 1.25 * 11874.0 / 3040.0;
  x3.actuator.constant_n_per_v *= 3.0;
  struct Case {
    const char* name;
    const config::Config* plant;
    double rpm;
    std::vector<double> depths_mm;
  };
  for (const Case& c : {Case{"leads swapped", &swapped, 700.0, {0.001, 0.3, 3.0, 5.0}},
                        Case{"1.25 x K_max", &k125, 700.0, {0.001}}, Case{"actuator 3 x", &x3, 1200.0, {0.001, 0.3}}}) {
    for (const double depth : c.depths_mm) {
      const auto r_off = cut_at(off, c.rpm, depth, c.plant);
      const auto r = cut_at(cell, c.rpm, depth, c.plant);
      print(c.name, r);
      ASSERT_EQ(r.segments.size(), 1U);
      ASSERT_EQ(r_off.segments.size(), 1U);
      const auto& s = r.segments[0];
      EXPECT_EQ(s.trip, "instability") << c.name << ", " << depth << " mm";
      EXPECT_GT(s.trip_s, 0.0) << c.name << ", " << depth << " mm: during the cut";
      EXPECT_GE(r.counters.growth_gain_fed, 1U)
          << c.name << ", " << depth << " mm: the probe found the gain feeding it";
      EXPECT_LE(s.peak_force_command_n, r.force_limit_n + 1e-9);
      const double t_off = r_off.segments[0].trip_s;
      std::printf("[ derate   ] %s, %.3f mm: tripped %s %.2f s into the cut without derating, %s %.2f s with it\n",
                  c.name, depth, r_off.segments[0].trip.c_str(), t_off, s.trip.c_str(), s.trip_s);
      if (depth < 1.0) {
        EXPECT_EQ(r_off.segments[0].trip, "instability");
        EXPECT_LE(s.trip_s, t_off + 0.6) << c.name << ", " << depth << " mm: the probe's cost";
      }
    }
  }
}

// The same without a speed schedule (C2 at K = 2000 at every speed; the actuator 3 x stronger: 1.25 x K_max),
// under a stable cut (0.3 mm) and a chattering one (1.3 mm). A fixed gain may feed the chatter of a speed it
// does not suit, so the probe that finds the gain feeding the growth holds it at half; back at full gain it
// grows again at the same speed: instability, latched.
TEST(Derate, ALoopUnstableOnItsOwnStillTripsWithTheSpindleTurning) {
  config::Config real = fixed_c2();
  real.actuator.constant_n_per_v *= 3.0;
  for (const double depth : {0.3, 1.3}) {
    const auto r = cut_at(fixed_c2(), 700.0, depth, &real);
    print("actuator 3 x", r);
    ASSERT_EQ(r.segments.size(), 1U);
    EXPECT_EQ(r.segments[0].trip, "instability") << depth << " mm";
    EXPECT_EQ(r.segments[0].state, "fault");
    EXPECT_GT(r.segments[0].trip_s, 0.0) << depth << " mm: tripped during the cut";
    EXPECT_GE(r.counters.growth_gain_fed, 1U) << "the probe found the gain feeding it";
    EXPECT_EQ(r.counters.trips[static_cast<std::size_t>(rt::Trip::kInstability)], 1U);
  }
}

// Swapped leads on the cell (sensor noise, drive vibration): with the spindle stopped the instability rule trips
// as it always did (1.40 s after activation); with the scheduled preset's spindle at 700 rpm (the band's set
// handed over and its K ramped in) it is probed, found fed by the gain, and trips.
TEST(Derate, SwappedLeadsTripOnTheCellWithTheSpindleStoppedOrTurning) {
  const config::Config cell = config::load_config_file(test::preset("horizontal_c2"));
  config::Config swapped = cell;
  swapped.plant.actuator_wiring = -1;
  for (const double rpm : {0.0, 700.0}) {
    rt::CellOptions o = rt::virtual_clock();
    o.plant_config = swapped;
    const auto r = rt::run(
        cell, 30.0,
        [rpm](rt::Cell& s) {
          if (rpm > 0.0) s.schedule(100, {rt::CommandKind::kSetSpindle, rpm});
        },
        o);
    ASSERT_EQ(r.s.trip, "instability") << rpm << " rpm";
    const std::size_t active = rt::first_state(r, rt::State::kActive), fault = rt::first_state(r, rt::State::kFault);
    ASSERT_LT(fault, r.frames.size());
    const double t = r.frames[fault].time_s - r.frames[active].time_s;
    std::printf("[ derate   ] the cell, leads swapped, %.0f rpm: instability %.2f s after activation (%llu probes)\n",
                rpm, t, static_cast<unsigned long long>(r.s.supervisor.derate_probes));
    if (rpm == 0.0) {
      EXPECT_EQ(r.s.supervisor.derate_probes, 0U);
      EXPECT_NEAR(t, 1.40, 0.2);
    } else {
      EXPECT_GE(r.s.supervisor.growth_gain_fed, 1U);
      EXPECT_LT(t, 10.0);
    }
  }
}

// The scheduled default preset on the cell with its sensor noise and 3 Hz drive vibration, the spindle started at
// 700 rpm (no cut; the band's set handed over and its K ramped in), a 1000 N hammer blow at the TCP every 1.3 s for
// 20 s: nothing is probed or derated. (Before blows were told from growth, a blow at the end of the quiet command's
// rising beat was probed, judged fed by the gain, and after the restore tripped.)
TEST(Derate, HammerBlowsAndTheDrivesWithTheSpindleTurningAreNotDerated) {
  rt::CellOptions o = rt::virtual_clock();
  o.impact_every_s = 1.3;
  const auto r = rt::run(
      rt::c2(), 20.0,
      [](rt::Cell& s) {
        s.schedule(100, {rt::CommandKind::kSetSpindle, 700.0});
      },
      o);
  EXPECT_EQ(r.s.trip, "none");
  EXPECT_EQ(r.s.supervisor.derate_probes, 0U);
  EXPECT_EQ(r.s.supervisor.saturation_derates, 0U);
  EXPECT_EQ(r.s.supervisor.derated_ticks, 0U);
}

// The same unstable loop on the cell with the spindle turning (no cut): probed, held, grown again, tripped; the
// recording replays it bit for bit (the derating's settings are in its header) and the summary counts it.
TEST(Derate, TheDeratingReplaysBitForBit) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "robodamp-derate-replay";
  std::filesystem::create_directories(dir);
  config::Config real = fixed_c2();
  real.actuator.constant_n_per_v *= 3.0;
  rt::CellOptions o = rt::virtual_clock();
  o.plant_config = real;
  o.record_path = (dir / "derate.rec").string();
  const auto r = rt::run(
      fixed_c2(), 30.0,
      [](rt::Cell& s) {
        s.schedule(100, {rt::CommandKind::kSetSpindle, 700.0});
      },
      o);
  for (const auto& e : r.s.events)
    std::printf("  %.3f %s %s\n", e.time_s, rt::to_string(e.kind), rt::to_string(e.trip));
  EXPECT_EQ(r.s.trip, "instability");
  EXPECT_GE(r.s.supervisor.derate_probes, 2U);
  EXPECT_GE(r.s.supervisor.growth_gain_fed, 1U);
  EXPECT_GT(r.s.supervisor.derated_ticks, 0U);
  std::size_t derated_frames = 0;
  for (const auto& f : r.frames) derated_frames += (f.flags & rt::kFlagDerated) ? 1U : 0U;
  EXPECT_EQ(derated_frames, r.s.supervisor.derated_ticks);
  const rt::ReplayResult rp = rt::replay(rt::read_recording(o.record_path));
  EXPECT_EQ(rp.frames, r.frames.size());
  EXPECT_EQ(rp.mismatches, 0U);
  EXPECT_EQ(rp.final_trip, "instability");
  const std::size_t active = rt::first_state(r, rt::State::kActive), fault = rt::first_state(r, rt::State::kFault);
  std::printf(
      "[ derate   ] the cell, actuator 3 x, spindle turning: instability after %.2f s active (%llu probes, %llu fed "
      "by the gain)\n",
      r.frames[fault].time_s - r.frames[active].time_s, static_cast<unsigned long long>(r.s.supervisor.derate_probes),
      static_cast<unsigned long long>(r.s.supervisor.growth_gain_fed));
  std::filesystem::remove_all(dir);
}

TEST(Derate, TheConfigurationNamesWhatItRefuses) {
  std::string yaml = test::read_file(test::preset("horizontal_c2"));
  yaml += "\nsupervision:\n  derate:\n    probe_blocks: 0\n    hold_factor: 1.5\n";
  test::replace_or_throw(yaml, "\nplant:\n", "\nplant:\n  actuator_wiring: 0\n");
  try {
    (void)config::parse_config(yaml, test::preset("horizontal_c2"));
    FAIL() << "accepted";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(
        what.find(
            "supervision.derate.probe_blocks = 0 (instability blocks) is out of range: allowed 1 <= value <= 1000"),
        std::string::npos)
        << what;
    EXPECT_NE(what.find("supervision.derate.hold_factor = 1.5 (x K) is out of range: allowed 0 <= value < 1 (x K)"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("plant.actuator_wiring = 0 is not a wiring: allowed 1 (as configured) or -1 (leads swapped)"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace robodamp
