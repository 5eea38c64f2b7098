// The controller scheduled by pose across two processes (docs/pose_dynamics.md, "The HIL emulator's
// trajectory"): the emulator moves the robot along a trajectory and measures the improvement at each dwell;
// the controller reads the joint registers and hands over between the regions' sets. The hand-drawn preset
// with scheduling on and off, and the schedule `robodamp pose tune` drew, at poses nobody measured.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "hil_files.hpp"
#include "rt/recording.hpp"
#include "rt/supervisor.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using nlohmann::json;
using test::Child;
using test::HilFiles;
using test::hil_files;

json read_json(const std::string& path) { return json::parse(test::read_file(path)); }

// The robot (the planar-robot study's model, config/hil_pose_schedule.yaml) dwells folded (joint 2 at 10 deg), moves
// over 6 s to stretched (100 deg) and dwells there; its dominant mode along the actuator moves from 9.2
// to 19.8 Hz. The controller in the other process reads the joint registers and hands over from the
// folded region's set to the stretched one's. Each dwell's improvement, measured by the emulator's
// impacts, stays within 10 % of the analysis at that pose; the hand-over's largest command step is no
// larger than twice the largest in the second before it (a swap without the fade jumps by the whole
// command). With scheduling off, the folded set runs on at the stretched pose and the loop trips safely.
TEST(Hil, PoseTrajectoryHandsOverBetweenRegionsAndSchedulingOffTrips) {
  const std::vector<std::string> trajectory{"--pose-at", "0:-100,10,90",  "--pose-at", "22:-100,10,90",
                                            "--pose-at", "28:-100,100,90", "--pose-at", "50:-100,100,90"};
  std::map<std::string, json> plant, run;
  std::string record;
  for (const std::string mode : {"on", "off"}) {
    const HilFiles f = hil_files("pose_" + mode, {}, "hil_pose_schedule");
    std::vector<std::string> pargs{"plant", "--config", f.config, "--pacing", "lockstep", "--json", f.plant_json};
    pargs.insert(pargs.end(), trajectory.begin(), trajectory.end());
    Child p(pargs, f.plant_log);
    std::vector<std::string> rargs{"run", "--config", f.config, "--clock", "virtual", "--duration", "50", "--json", f.run_json};
    if (mode == "on") record = f.dir + "/run.rec", rargs.insert(rargs.end(), {"--record", record});
    if (mode == "off") rargs.push_back("--no-pose-schedule");
    Child r(rargs, f.run_log);
    const int run_status = r.wait();
    ASSERT_EQ(p.wait(), 0) << test::read_file(f.plant_log);
    ASSERT_EQ(run_status, mode == "on" ? 0 : 4) << test::read_file(f.run_log);
    plant[mode] = read_json(f.plant_json);
    run[mode] = read_json(f.run_json);
  }
  // Scheduled: armed, one hand-over folded -> stretched, no trip, nothing out of the map.
  const json& on = run["on"];
  EXPECT_EQ(on["trip"], "none");
  EXPECT_EQ(on["arming"]["outcome"], "armed");
  EXPECT_EQ(on["modbus"]["pose_changes"], 2);
  EXPECT_EQ(on["modbus"]["pose_out_of_map_polls"], 0);
  EXPECT_EQ(on["supervisor"]["pose_regions"], 2);
  EXPECT_EQ(on["supervisor"]["pose_out_of_map"], 0);
  EXPECT_EQ(on["supervisor"]["params_selected"], 1);
  EXPECT_EQ(on["supervisor"]["params_refused"], 0);
  EXPECT_EQ(on["supervisor"]["active_parameter_set"], 1);
  const json& dwells = plant["on"]["pose"]["dwells"];
  ASSERT_EQ(dwells.size(), 2u);
  EXPECT_EQ(dwells[0]["region"], "folded");
  EXPECT_EQ(dwells[1]["region"], "stretched");
  const double f0 = dwells[0]["dominant_hz"].get<double>(), f1 = dwells[1]["dominant_hz"].get<double>();
  EXPECT_GE(std::abs(f1 / f0 - 1.0), 0.30) << f0 << " -> " << f1 << " Hz";
  for (const auto& d : dwells) {
    const double measured = d["measured_improvement_pct"].get<double>(), predicted = d["predicted_improvement_pct"].get<double>();
    std::cout << d["region"] << " at " << d["joints_deg"].dump() << ": dominant " << d["dominant_hz"] << " Hz, improvement "
              << measured << " % measured, " << predicted << " % predicted\n";
    EXPECT_GE(d["records"].get<int>(), 2);
    EXPECT_GT(predicted, 50.0);
    EXPECT_NEAR(measured / predicted, 1.0, 0.10) << d.dump();
  }
  // The hand-over: the set_pose_region command of the crossing, then fade out, swap, fade in.
  const rt::Recording rec = rt::read_recording(record);
  std::vector<std::size_t> pose_ticks;
  for (std::size_t i = 0; i < rec.frames.size(); ++i)
    if (static_cast<rt::CommandKind>(rec.frames[i].command_kind) == rt::CommandKind::kSetPoseRegion) pose_ticks.push_back(i);
  ASSERT_EQ(pose_ticks.size(), 2u);
  const std::size_t cross = pose_ticks[1], second = 5000;
  EXPECT_EQ(rec.frames[cross].command_value, 1.0);
  ASSERT_GT(cross, second);
  auto max_step = [&](std::size_t from, std::size_t to) {
    double m = 0.0;
    for (std::size_t i = from + 1; i < std::min(to, rec.frames.size()); ++i)
      m = std::max(m, std::abs(rec.frames[i].command_v - rec.frames[i - 1].command_v));
    return m;
  };
  const double before = max_step(cross - second, cross), during = max_step(cross, cross + 5 * second);
  std::cout << "hand-over at " << rec.frames[cross].time_s << " s: largest command step " << 1e3 * during
            << " mV/tick in the 5 s after it, " << 1e3 * before << " mV/tick in the second before\n";
  EXPECT_GT(before, 0.0);
  EXPECT_LE(during, 2.0 * before);
  // Scheduling off: the folded set at the stretched pose grows an oscillation and trips to the safe state.
  const json& off = run["off"];
  std::cout << "scheduling off: trip " << off["trip"] << " at " << off["trip_timing"]["trip_s"] << " s, stretched dwell "
            << plant["off"]["pose"]["dwells"][1]["measured_improvement_pct"] << " % measured\n";
  EXPECT_TRUE(off["trip"] == "instability" || off["trip"] == "saturation") << off["trip"];
  EXPECT_GT(off["trip_timing"]["trip_s"].get<double>(), 22.0);
  EXPECT_EQ(off["final_state"], "fault");
  EXPECT_LE(off["trip_timing"]["ticks_to_safe"].get<int>(), 100);
  EXPECT_EQ(off["supervisor"]["pose_regions"], 0);
}

// The schedule `robodamp pose tune` drew and tuned for the planar robot (config/hil_pose_tuned.yaml, its
// command in the file's header) along a path through three poses nobody tuned or measured at: each dwell's
// improvement, measured by the emulator's impacts, within 5 points of the analysis of the set that runs
// there; no trip through the hand-overs on the way, and no command step while moving larger than the ones
// the impacts cause at the dwells.
TEST(Hil, TunedScheduleAtPosesNobodyMeasuredDampsAsPredicted) {
  const std::vector<std::string> trajectory{"--pose-at", "0:-100,20,90",  "--pose-at", "24:-100,20,90", "--pose-at", "30:-100,85,90",
                                            "--pose-at", "54:-100,85,90", "--pose-at", "58:-100,125,90", "--pose-at", "82:-100,125,90"};
  // Into each dwell the emulator waits 6 s before its impacts: crossing the narrow regions the hand-overs
  // queue up, each set warming up for its slowest pole (about 3 s) before its swap.
  const HilFiles f = hil_files("pose_tuned", {{"settle_s: 3 ", "settle_s: 6 "}}, "hil_pose_tuned");
  std::vector<std::string> pargs{"plant", "--config", f.config, "--pacing", "lockstep", "--json", f.plant_json};
  pargs.insert(pargs.end(), trajectory.begin(), trajectory.end());
  Child p(pargs, f.plant_log);
  const std::string record = f.dir + "/run.rec";
  Child r({"run", "--config", f.config, "--clock", "virtual", "--duration", "82", "--json", f.run_json, "--record", record}, f.run_log);
  const int run_status = r.wait();
  ASSERT_EQ(p.wait(), 0) << test::read_file(f.plant_log);
  ASSERT_EQ(run_status, 0) << test::read_file(f.run_log);
  const json run = read_json(f.run_json), plant = read_json(f.plant_json);
  EXPECT_EQ(run["trip"], "none");
  EXPECT_EQ(run["arming"]["outcome"], "armed");
  EXPECT_EQ(run["supervisor"]["pose_out_of_map"], 0);
  EXPECT_GE(run["modbus"]["pose_changes"].get<int>(), 3);
  const json& dwells = plant["pose"]["dwells"];
  ASSERT_EQ(dwells.size(), 3U);
  for (const auto& d : dwells) {
    const double measured = d["measured_improvement_pct"].get<double>(), predicted = d["predicted_improvement_pct"].get<double>();
    std::cout << d["region"] << " at " << d["joints_deg"].dump() << ": dominant " << d["dominant_hz"] << " Hz, improvement "
              << measured << " % measured, " << predicted << " % predicted, coherence " << d["coherence_min"] << "\n";
    EXPECT_GE(d["records"].get<int>(), 2);
    EXPECT_GT(predicted, 20.0) << d.dump();
    EXPECT_NEAR(measured, predicted, 5.0) << d.dump();
  }
  const rt::Recording rec = rt::read_recording(record);
  double moving = 0.0, dwelling = 0.0;
  for (std::size_t i = 1; i < rec.frames.size(); ++i) {
    const double t = rec.frames[i].time_s, step = std::abs(rec.frames[i].command_v - rec.frames[i - 1].command_v);
    if ((t > 24.0 && t < 30.0) || (t > 54.0 && t < 58.0)) moving = std::max(moving, step);
    else if (t > 5.0) dwelling = std::max(dwelling, step);
  }
  std::cout << "largest command step moving " << 1e3 * moving << " mV, at the dwells " << 1e3 * dwelling << " mV\n";
  EXPECT_GT(dwelling, 0.0);
  EXPECT_LE(moving, dwelling);
}

}  // namespace
}  // namespace robodamp
