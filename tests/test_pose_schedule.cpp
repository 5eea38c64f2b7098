// The controller scheduled by pose (docs/pose_dynamics.md, "Scheduling by pose"): the pose_schedule
// section's checks (holes, travel, registers), the region lookup with its hysteresis, the per-region sets
// and their refusal, the robot model's modes as the loop's plant, the plant following a pose, the
// supervisor's hand-over and out-of-map trip, and the cell standing at a pose in process.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <string>

#include "analysis/loop_model.hpp"
#include "analysis/mode_improvement.hpp"
#include "analysis/pose_schedule.hpp"
#include "cell_util.hpp"
#include "robot/robot_model.hpp"
#include "rt/supervisor.hpp"
#include "runtime/cell.hpp"
#include "sim_plant/plant.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

const std::string kPreset = "pose_scheduled_c2";

std::string preset_text() { return test::read_file(test::preset(kPreset)); }

void replace(std::string& s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  ASSERT_NE(p, std::string::npos) << from;
  s.replace(p, from.size(), to);
}

// The preset with edits, parsed as if it were the preset file (its model path resolves the same way).
config::Config edited(const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = preset_text();
  for (const auto& [from, to] : edits) replace(text, from, to);
  return config::parse_config(text, test::preset(kPreset));
}

std::string problems_of(const std::vector<std::pair<std::string, std::string>>& edits) {
  try {
    (void)edited(edits);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::string kFolded = "    - {name: folded, min_deg: [-102, 0, 88], max_deg: [-98, 25, 92], gain_ns_per_m: 250}";

TEST(PoseScheduleConfig, PresetReadsItsRegionsAndLookupKeepsTheCurrentRegionInTheOverlap) {
  const config::Config cfg = config::load_config_file(test::preset(kPreset));
  ASSERT_TRUE(cfg.pose_schedule);
  const auto& s = *cfg.pose_schedule;
  EXPECT_EQ(s.axis, 0);
  EXPECT_EQ(s.joints(), 3u);
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(s.regions[0].gain_ns_per_m, 250.0);
  const double overlap[] = {-100.0, 22.0, 90.0}, folded[] = {-100.0, 10.0, 90.0}, stretched[] = {-100.0, 80.0, 90.0};
  EXPECT_EQ(config::region_of(s, folded, 3), 0u);
  EXPECT_EQ(config::region_of(s, stretched, 3), 1u);
  EXPECT_EQ(config::region_of(s, overlap, 3), 0u);     // the first that holds it
  EXPECT_EQ(config::region_of(s, overlap, 3, 1), 1u);  // coming from stretched: stays there
  EXPECT_EQ(config::region_of(s, overlap, 3, 0), 0u);
  const double outside[] = {-100.0, 150.0, 90.0}, nan[] = {-100.0, std::nan(""), 90.0};
  EXPECT_FALSE(config::region_of(s, outside, 3));
  EXPECT_FALSE(config::region_of(s, nan, 3));
  EXPECT_FALSE(config::region_of(s, folded, 2));  // a wrong joint count is no pose
}

TEST(PoseScheduleConfig, AHoleInTheMapIsRefusedWithAPoseInIt) {
  const std::string e =
      problems_of({{kFolded, "    - {name: folded, min_deg: [-102, 0, 88], max_deg: [-98, 15, 92]}"}});
  EXPECT_NE(e.find("pose_schedule.regions: leave a hole in the workspace"), std::string::npos) << e;
  EXPECT_NE(e.find("[-100, 17.5, 90] deg"), std::string::npos) << e;  // the hole is joint 2 in (15, 20)
}

TEST(PoseScheduleConfig, NonPhysicalOrInconsistentSectionsAreRefusedByName) {
  // Outside the joint's travel (the model's joint 2 travels 0..170 deg).
  std::string e = problems_of({{"max_deg: [-98, 140, 92]}\n", "max_deg: [-98, 175, 92]}\n"}});
  EXPECT_NE(e.find("pose_schedule.workspace.max_deg[1] = 175 deg is out of range"), std::string::npos) << e;
  EXPECT_NE(e.find("joint 2's travel"), std::string::npos) << e;
  // A box upside down, a wrong joint count, a duplicate name.
  e = problems_of({{kFolded, "    - {name: folded, min_deg: [-98, 0, 88], max_deg: [-102, 25, 92]}"}});
  EXPECT_NE(e.find("pose_schedule.regions[0].max_deg[0] = -102 deg is below min_deg = -98 deg"), std::string::npos)
      << e;
  e = problems_of({{kFolded, "    - {name: folded, min_deg: [-102, 0], max_deg: [-98, 25]}"}});
  EXPECT_NE(e.find("pose_schedule.regions[0].min_deg: has 2 angles; the robot model"), std::string::npos) << e;
  e = problems_of({{"{name: stretched,", "{name: folded,"}});
  EXPECT_NE(e.find("names regions[0] too"), std::string::npos) << e;
  // A model that is not there, an unknown axis, a negative gain.
  e = problems_of({{"model: ../robots/planar_three_link.yaml", "model: ../robots/none.yaml"}});
  EXPECT_NE(e.find("pose_schedule.model = '../robots/none.yaml'"), std::string::npos) << e;
  e = problems_of({{"axis: x ", "axis: z "}});
  EXPECT_NE(e.find("pose_schedule.axis"), std::string::npos) << e;
  e = problems_of({{"gain_ns_per_m: 250}", "gain_ns_per_m: -5}"}});
  EXPECT_NE(e.find("pose_schedule.regions[0].gain_ns_per_m = -5 N s/m is out of range"), std::string::npos) << e;
  // pose_schedule with parameter_sets.
  std::string text = preset_text() + "\nparameter_sets: {vertical: vertical_c1.yaml}\n";
  try {
    (void)config::parse_config(text, test::preset(kPreset));
    ADD_FAILURE() << "pose_schedule and parameter_sets accepted together";
  } catch (const config::ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("schedules by pose or by mounting, not both"), std::string::npos)
        << err.what();
  }
}

TEST(PoseScheduleConfig, JointRegistersMustNotOverlapTheOtherRobotRegisters) {
  config::Config hil = config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_pose_schedule.yaml");
  ASSERT_TRUE(hil.modbus);
  EXPECT_EQ(hil.modbus->robot.joints_register, 10);
  EXPECT_EQ(hil.modbus->robot.deg_per_count, 0.01);
  std::string text = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_pose_schedule.yaml");
  replace(text, "joints_register: 10 ", "joints_register: 0 ");  // 0..2 holds the mounting register
  try {
    (void)config::parse_config(text, std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_pose_schedule.yaml");
    ADD_FAILURE() << "overlapping registers accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("modbus.robot.joints_register = 0 covers registers 0-2"), std::string::npos)
        << e.what();
  }
}

// The pose over DDS (dds.joint_states): one name per joint, each once, with a pose schedule, and not beside the
// Modbus joint registers; each refused by key with the reason.
TEST(PoseScheduleConfig, JointStatesNameEachJointOnceAndAreTheOnlySourceOfThePose) {
  const std::string path = test::preset(kPreset);
  const std::string base = test::read_file(path);
  const auto error_of = [&](const std::string& text) {
    try {
      (void)config::parse_config(text, path);
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const config::Config ok =
      config::parse_config(base + "\ndds:\n  joint_states: {names: [a1, a2, a3], timeout_s: 0.2}\n", path);
  ASSERT_TRUE(ok.dds && ok.dds->joint_states);
  EXPECT_EQ(ok.dds->joint_states->names, (std::vector<std::string>{"a1", "a2", "a3"}));
  EXPECT_EQ(ok.dds->joint_states->topic, "rt/joint_states");
  EXPECT_EQ(ok.dds->joint_states->timeout_s, 0.2);
  EXPECT_EQ(ok.dds->joint_states->settle_samples, 3);
  EXPECT_NE(error_of(base + "\ndds:\n  joint_states: {names: [a1, a2]}\n")
                .find("dds.joint_states.names: has 2 names; pose_schedule has 3 joints"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  joint_states: {names: [a1, a2, a1]}\n")
                .find("dds.joint_states.names[2] = 'a1' is named twice: each joint once"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  joint_states: {names: a1}\n").find("dds.joint_states.names: must be a list"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  joint_states: {names: [a1, a2, a3], timeout_s: 0}\n")
                .find("dds.joint_states.timeout_s"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  joint_states: {topic: rt/joint_states}\n").find("dds.joint_states.names"),
            std::string::npos);
  const std::string hil = std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_pose_schedule.yaml";
  std::string both = test::read_file(hil);
  replace(both, "  parameter_writes: false", "  joint_states: {names: [a1, a2, a3]}\n  parameter_writes: false");
  try {
    (void)config::parse_config(both, hil);
    ADD_FAILURE() << "two sources of the pose accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("and modbus.robot.joints_register = 10 both give the pose: choose one source"),
              std::string::npos)
        << e.what();
  }
  const std::string no_schedule =
      test::read_file(test::preset("horizontal_c2")) + "\ndds:\n  joint_states: {names: [a1]}\n";
  EXPECT_NE(error_of(no_schedule).find("dds.joint_states: is set without pose_schedule"), std::string::npos)
      << error_of(no_schedule);
  // dds.path_ahead: the robot program's trajectory, its names its own or the joint states'.
  const config::Config ahead =
      config::parse_config(base + "\ndds:\n  path_ahead:\n    names: [a1, a2, a3]\n    hold_s: 4\n", path);
  ASSERT_TRUE(ahead.dds && ahead.dds->path_ahead);
  EXPECT_EQ(ahead.dds->path_ahead->topic, "rt/joint_trajectory");
  EXPECT_EQ(ahead.dds->path_ahead->hold_s, 4.0);
  EXPECT_NO_THROW(
      (void)config::parse_config(base + "\ndds:\n  joint_states: {names: [a1, a2, a3]}\n  path_ahead: {}\n", path));
  EXPECT_NE(error_of(base + "\ndds:\n  path_ahead: {}\n").find("dds.path_ahead: needs names"), std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  path_ahead: {names: [a1, a2]}\n")
                .find("dds.path_ahead.names: has 2 names; pose_schedule has 3 joints"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  path_ahead: {names: [a1, a2, a3], hold_s: 0}\n").find("dds.path_ahead.hold_s"),
            std::string::npos);
  EXPECT_NE(error_of(base + "\ndds:\n  path_ahead: {names: [a1, a2, a2]}\n")
                .find("dds.path_ahead.names[2] = 'a2' is named twice"),
            std::string::npos);
  const std::string no_schedule_path =
      test::read_file(test::preset("horizontal_c2")) + "\ndds:\n  path_ahead: {names: [a1]}\n";
  EXPECT_NE(error_of(no_schedule_path).find("dds.path_ahead: is set without pose_schedule"), std::string::npos);
}

// The robot model's modes as the loop's modal table: the modal-stiffness form with damping from each
// mode's loss factor reproduces the assembled model's TCP receptance along the axis at the dominant peak.
TEST(PoseSchedule, PoseModesReproduceTheRobotModelsReceptanceAtTheDominantPeak) {
  const config::RobotModelConfig model =
      config::load_robot_model(std::string(ROBODAMP_SOURCE_DIR) + "/config/robots/planar_three_link.yaml");
  for (const std::vector<double>& q : {std::vector<double>{-100, 10, 90}, std::vector<double>{-100, 100, 90}}) {
    const analysis::PoseModes pm = analysis::pose_modes(model, q, 0, 3);
    ASSERT_EQ(pm.modes.size(), 3u);
    const auto& d = pm.modes[pm.dominant];
    const robot::PlanarChain chain = robot::at_pose(model, q);
    const double f = d.natural_freq_hz;
    const std::complex<double> exact = chain.tcp_frf_direct(f)(0, 0);
    std::complex<double> modal = 0.0;
    for (const auto& m : pm.modes) {
      const double r = f / m.natural_freq_hz;
      modal += 1.0 / (m.stiffness_n_per_m * std::complex<double>(1.0 - r * r, 2.0 * m.damping_ratio * r));
    }
    EXPECT_NEAR(std::abs(modal) / std::abs(exact), 1.0, 0.03) << config::describe_pose(q) << " at " << f << " Hz";
  }
}

TEST(PoseSchedule, EachRegionGetsASetMatchedAtItsDominantModeAndTooMuchGainIsRefusedWithThePose) {
  const config::Config cfg = config::load_config_file(test::preset(kPreset));
  const analysis::PoseScheduleAnalysis a = analysis::analyse_pose_schedule(cfg);
  ASSERT_EQ(a.regions.size(), 2u);
  const auto& folded = a.regions[0];
  const auto& stretched = a.regions[1];
  EXPECT_NEAR(folded.dominant_hz, 9.2, 0.2);
  EXPECT_NEAR(stretched.dominant_hz, 20.2, 0.5);
  EXPECT_EQ(folded.polarity, 1);
  EXPECT_EQ(stretched.polarity, -1);  // the compensator's phase at 20 Hz turns the other way
  EXPECT_EQ(folded.grid_poses, 27);
  EXPECT_DOUBLE_EQ(*folded.config.controller.match_freq_hz, folded.dominant_hz);
  for (const auto& r : a.regions) {
    EXPECT_LE(r.gain_ns_per_m, cfg.supervision.max_gain_fraction * r.k_max_ns_per_m) << r.name;
    EXPECT_TRUE(analysis::LoopModel(r.config).stable(r.gain_ns_per_m, r.polarity)) << r.name;
    EXPECT_GT(r.improvement_centre_pct, 50.0) << r.name;
  }
  // The folded region at K = 1000 N s/m: unstable at some pose of its grid, refused with it.
  try {
    (void)analysis::analyse_pose_schedule(
        edited({{"max_deg: [-98, 25, 92], gain_ns_per_m: 250}", "max_deg: [-98, 25, 92], gain_ns_per_m: 1000}"}}));
    ADD_FAILURE() << "an unstable region accepted";
  } catch (const config::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("pose_schedule.regions[0]: has no stable set: region 'folded' at ["), std::string::npos) << w;
    EXPECT_NE(w.find("the loop is unstable at K = 1000 N s/m (K_max there"), std::string::npos) << w;
  }
}

// Each region's worst mode over its grid (analysis/mode_improvement.hpp): the preset's matched sets make the
// other mode worse than open loop at the edge where the two modes trade places (issue 33's "one matched
// compensator makes the 9.5 Hz peak worse"): the folded set (matched at 9.2 Hz) the 21-22 Hz mode, the
// stretched set (matched at 20 Hz, polarity -1) the 9.2 Hz mode; the worst pose lies in the region, and
// at the region's centre the matched mode itself improves.
TEST(PoseSchedule, EachRegionReportsTheModeItsSetMakesWorstOverItsGrid) {
  const config::Config cfg = config::load_config_file(test::preset(kPreset));
  const analysis::PoseScheduleAnalysis a = analysis::analyse_pose_schedule(cfg);
  ASSERT_EQ(a.regions.size(), 2u);
  for (std::size_t i = 0; i < a.regions.size(); ++i) {
    const auto& r = a.regions[i];
    const auto& box = cfg.pose_schedule->regions[i];
    EXPECT_LT(r.worst_mode_improvement_pct, -20.0) << r.name;
    EXPECT_GT(std::abs(r.worst_mode_hz - r.dominant_hz), 5.0) << r.name << ": not the matched mode";
    ASSERT_EQ(r.worst_mode_pose_deg.size(), box.min_deg.size());
    for (std::size_t j = 0; j < box.min_deg.size(); ++j) {
      EXPECT_GE(r.worst_mode_pose_deg[j], box.min_deg[j]) << r.name;
      EXPECT_LE(r.worst_mode_pose_deg[j], box.max_deg[j]) << r.name;
    }
    const analysis::LoopModel centre(r.config);
    double matched = -1e9;
    for (const auto& mi : analysis::mode_improvements(centre, r.gain_ns_per_m, r.polarity))
      if (std::abs(mi.freq_hz - r.dominant_hz) < 0.01) matched = mi.improvement_pct;
    EXPECT_GT(matched, 50.0) << r.name << ": the matched mode at the centre";
  }
  EXPECT_NEAR(a.regions[0].worst_mode_hz, 21.7, 1.0);
  EXPECT_NEAR(a.regions[1].worst_mode_hz, 9.3, 0.5);
}

// A plant retuned to the structure it has continues exactly; retuned to another pose, it keeps its state.
TEST(PoseSchedule, PlantRetuneCarriesTheStateAcrossPoses) {
  const config::Config cfg = config::load_config_file(test::preset(kPreset));
  const analysis::PoseScheduleAnalysis a = analysis::analyse_pose_schedule(cfg);
  const auto model_at = [&](std::vector<double> q) {
    return sim::build_plant_model(analysis::config_at_pose(cfg, analysis::pose_modes(a.model, q, 0, 3)));
  };
  sim::Plant p(model_at({-100, 10, 90}), cfg), q(model_at({-100, 10, 90}), cfg);
  for (int k = 0; k < 500; ++k) p.step(k < 50 ? 1.0 : 0.0), q.step(k < 50 ? 1.0 : 0.0);
  q.retune(model_at({-100, 10, 90}));
  for (int k = 0; k < 500; ++k) {
    p.step(0.0), q.step(0.0);
    ASSERT_EQ(p.acceleration_mps2(0), q.acceleration_mps2(0)) << k;
  }
  const sim::Vector before = q.state();
  q.retune(model_at({-100, 12, 90}));
  EXPECT_EQ((q.state() - before).norm(), 0.0);
  EXPECT_GT(before.norm(), 0.0);
}

rt::ParameterSet set_of(const analysis::RegionSet& r) {
  return {analysis::LoopModel(r.config).chain().params, true, r.k_max_ns_per_m};
}

rt::TickInput live_tick(double accel = 0.0) {
  rt::TickInput in;
  in.dt_s = 1.0 / 5000.0;
  in.accel_mps2 = accel;
  in.fresh = true;
  in.amplifier_ready = true;
  return in;
}

// The supervisor with a schedule: no arming until the pose is in a region and its set handed over; the
// hand-over follows the pose; out of the map (or NaN, or no such set) trips to the safe state.
TEST(PoseSchedule, SupervisorArmsOnlyInARegionFollowsThePoseAndTripsOutOfTheMap) {
  const config::Config cfg = config::load_config_file(test::preset(kPreset));
  const analysis::PoseScheduleAnalysis a = analysis::analyse_pose_schedule(cfg);
  rt::SupervisorSettings s = config::supervisor_settings(a.regions[0].config, true, a.regions[0].k_max_ns_per_m);
  s.pose_scheduled = true;
  rt::Supervisor sup(s, set_of(a.regions[0]).params);
  ASSERT_EQ(sup.add_parameter_set(set_of(a.regions[1])), 1u);
  auto run = [&](int ticks, rt::OperatorCommand c = {}) {
    for (int i = 0; i < ticks; ++i) {
      rt::TickInput in = live_tick(0.01 * std::sin(i * 0.01));
      if (i == 0) in.command = c;
      (void)sup.step(in);
    }
  };
  run(100);  // the sensor live
  run(10, {rt::CommandKind::kArm, 0.0});
  EXPECT_EQ(sup.state(), rt::State::kDisabled);
  EXPECT_EQ(sup.last_arm_refusal(), rt::ArmRefusal::kPoseUnknown);
  run(10, {rt::CommandKind::kSetPoseRegion, 1.0});  // stretched: hand-over from set 0
  EXPECT_EQ(sup.active_parameter_set(), 1u);
  EXPECT_EQ(sup.running_parameter_set(), 0u) << "set 0's chain runs until the swap (the live limits are its)";
  run(10, {rt::CommandKind::kArm, 0.0});
  EXPECT_EQ(sup.last_arm_refusal(), rt::ArmRefusal::kPoseUnknown) << "armed during the hand-over";
  run(100000);  // the hand-over's fade and the new chain's settling
  ASSERT_FALSE(sup.controller().handover_pending());
  EXPECT_EQ(sup.running_parameter_set(), 1u) << "swapped";
  run(2000, {rt::CommandKind::kArm, 0.0});
  EXPECT_EQ(sup.state(), rt::State::kActive);
  run(10, {rt::CommandKind::kSetPoseRegion, 0.0});  // back to folded while active
  EXPECT_EQ(sup.active_parameter_set(), 0u);
  EXPECT_EQ(sup.state(), rt::State::kActive);
  run(10, {rt::CommandKind::kSetPoseRegion, -1.0});  // out of the map
  EXPECT_EQ(sup.state(), rt::State::kFault);
  EXPECT_EQ(sup.latched_trip(), rt::Trip::kPoseOutOfMap);
  run(200);  // the trip ramp
  run(10, {rt::CommandKind::kResetFault, 0.0});
  run(10, {rt::CommandKind::kArm, 0.0});
  EXPECT_EQ(sup.last_arm_refusal(), rt::ArmRefusal::kPoseUnknown) << "armed with the pose unknown";
  for (double bad : {std::nan(""), 7.0, 0.5}) run(1, {rt::CommandKind::kSetPoseRegion, bad});
  EXPECT_EQ(sup.counters().pose_out_of_map, 4u);
  EXPECT_EQ(sup.counters().trips[static_cast<std::size_t>(rt::Trip::kPoseOutOfMap)], 1u);
  EXPECT_EQ(sup.state(), rt::State::kDisabled);
}

// In process: the robot standing stretched; the schedule hands over to the stretched set and the loop
// runs without a trip; with scheduling off the folded set there grows an oscillation and trips safely.
TEST(PoseSchedule, CellAtAStretchedPoseRunsItsRegionsSetAndTheFoldedSetTrips) {
  for (const bool off : {false, true}) {
    runtime::CellOptions o;
    o.clock = config::ClockKind::kVirtual;
    o.impact_every_s = 0.0;
    o.pose_deg = {-100.0, 100.0, 90.0};
    o.pose_schedule_off = off;
    runtime::Cell cell(config::load_config_file(test::preset(kPreset)), o);
    test::configure(cell);
    ASSERT_TRUE(cell.run(off ? 8.0 : 12.0).ok());
    const runtime::RunSummary& s = cell.summary();
    if (!off) {
      EXPECT_EQ(s.trip, "none");
      EXPECT_EQ(s.arming.outcome, runtime::ArmingOutcome::kArmed);
      EXPECT_EQ(s.active_parameter_set, 1u);
      EXPECT_EQ(s.supervisor.pose_regions, 1u);
    } else {
      EXPECT_TRUE(s.trip == "instability" || s.trip == "saturation") << s.trip;
      EXPECT_EQ(s.final_state, "fault");
      EXPECT_EQ(s.active_parameter_set, 0u);
    }
  }
}

TEST(PoseSchedule, CellRefusesAPoseOutsideTheJointsTravel) {
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.pose_deg = {-100.0, 200.0, 90.0};
  runtime::Cell cell(config::load_config_file(test::preset(kPreset)), o);
  const runtime::Status s = cell.configure();
  EXPECT_EQ(s.kind, runtime::StatusKind::kConfigError);
  EXPECT_NE(s.message.find("--pose: joint 2 = 200 deg is out of range"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace robodamp
