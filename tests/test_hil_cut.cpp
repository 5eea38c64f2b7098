// The regenerative cut across processes: `robodamp plant --cut JOB` cuts against the emulated robot
// (hil/regenerative_cut.hpp) while `robodamp run` controls it through CAN frames and Modbus, in lockstep.
// Its chatter verdict is compared with the in-process damped cut (`robodamp cut --damped`, the Controller
// and the plant in one loop) at the same speed, depth and revolutions, both ways.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "hil_files.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using nlohmann::json;
using test::Child;

const std::string kJob = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml";

struct Verdicts {
  json hil, in_process, run;
};

// 150 revolutions at 700 rpm (12.9 s) from about 4.5 s: an 18 s run.
Verdicts cut_both_ways(const std::string& name, const std::string& depth_mm) {
  const test::HilFiles f = test::hil_files(name);
  Verdicts v;
  Child plant({"plant", "--config", f.config, "--pacing", "lockstep", "--no-impacts", "--cut", kJob, "--cut-rpm", "700",
               "--cut-axial-mm", depth_mm, "--cut-revs", "150", "--json", f.plant_json},
              f.plant_log);
  Child run({"run", "--config", f.config, "--clock", "virtual", "--duration", "18", "--json", f.run_json}, f.run_log);
  EXPECT_EQ(run.wait(), 0) << test::read_file(f.run_log);
  EXPECT_EQ(plant.wait(), 0) << test::read_file(f.plant_log);
  const std::string in_process_json = f.dir + "/cut.json";
  Child cut({"cut", "--config", kJob, "--rpm", "700", "--axial-mm", depth_mm, "--revs", "150", "--damped", "--json",
             in_process_json},
            f.dir + "/cut.log");
  EXPECT_EQ(cut.wait(), 0) << test::read_file(f.dir + "/cut.log");
  v.hil = json::parse(test::read_file(f.plant_json))["regenerative_cut"];
  v.run = json::parse(test::read_file(f.run_json));
  v.in_process = json::parse(test::read_file(in_process_json));
  return v;
}

TEST(HilCut, TheEmulatorsRegenerativeCutAgreesWithTheInProcessCutBothWays) {
  // The default preset's damped limit at 700 rpm is about 0.78 mm (cut --damped --critical).
  const Verdicts stable = cut_both_ways("regen_stable", "0.70");
  ASSERT_TRUE(stable.hil["complete"].get<bool>()) << stable.hil.dump();
  EXPECT_EQ(stable.run["trip"], "none");
  EXPECT_DOUBLE_EQ(stable.hil["rpm"].get<double>(), stable.in_process["rpm"].get<double>());
  EXPECT_EQ(stable.in_process["classification"], "stable");
  EXPECT_EQ(stable.hil["classification"], "stable") << stable.hil.dump();

  const Verdicts chatter = cut_both_ways("regen_chatter", "0.85");
  ASSERT_TRUE(chatter.hil["complete"].get<bool>()) << chatter.hil.dump();
  EXPECT_EQ(chatter.run["trip"], "none");
  EXPECT_EQ(chatter.in_process["classification"], "hopf");
  EXPECT_EQ(chatter.hil["classification"], "hopf") << chatter.hil.dump();
  EXPECT_NEAR(chatter.hil["chatter_hz"].get<double>(), chatter.in_process["chatter_hz"].get<double>(), 0.2);
  // The same regeneration: the once-per-tooth differences at the same share of the motion (the emulator's
  // record has the drives' 3 Hz vibration fitted out; the in-process plant has none).
  EXPECT_NEAR(chatter.hil["once_per_tooth_ratio"].get<double>() / chatter.in_process["once_per_tooth_ratio"].get<double>(),
              1.0, 0.1);
}

// The critical depth by bisection across processes (`cut --critical --hil CELL`, each step a pair of
// processes) against the in-process bisection, damped, at 700 rpm: within 5 % (measured: within the
// emulator's 1 % bisection step).
TEST(HilCut, TheCriticalDepthAcrossProcessesMatchesTheInProcessOne) {
  const test::HilFiles f = test::hil_files("regen_critical");
  const std::string out = f.dir + "/critical.json";
  Child cut({"cut", "--config", kJob, "--rpm", "700", "--damped", "--critical", "--hil", f.config, "--json", out},
            f.dir + "/critical.log");
  ASSERT_EQ(cut.wait(), 0) << test::read_file(f.dir + "/critical.log");
  const json c = json::parse(test::read_file(out))["critical"][0];
  const double in_process = c["critical_depth_mm"].get<double>(), across = c["hil"]["critical_depth_mm"].get<double>();
  EXPECT_NEAR(across / in_process, 1.0, 0.05) << c.dump();
  EXPECT_EQ(c["hil"]["above"], "hopf");
  EXPECT_NEAR(c["hil"]["chatter_hz"].get<double>(), c["chatter_hz"].get<double>(), 0.3);
  EXPECT_GE(c["hil"]["cuts"].get<int>(), 5);
}

TEST(HilCut, BadCutOptionsAreRefusedByName) {
  const test::HilFiles f = test::hil_files("regen_bad");
  Child depth({"plant", "--config", f.config, "--cut", kJob, "--cut-axial-mm", "-1"}, f.dir + "/depth.log");
  EXPECT_EQ(depth.wait(), 2);
  EXPECT_NE(test::read_file(f.dir + "/depth.log").find("--cut-axial-mm"), std::string::npos) << test::read_file(f.dir + "/depth.log");
  Child nan({"plant", "--config", f.config, "--cut", kJob, "--cut-rpm", "nan"}, f.dir + "/nan.log");
  EXPECT_EQ(nan.wait(), 2);
  EXPECT_NE(test::read_file(f.dir + "/nan.log").find("--cut-rpm"), std::string::npos) << test::read_file(f.dir + "/nan.log");
  // One speed only: a spindle profile with the regenerative cut is refused.
  Child ramp({"plant", "--config", f.config, "--cut", kJob, "--spindle", "1:5000"}, f.dir + "/ramp.log");
  EXPECT_EQ(ramp.wait(), 2);
  EXPECT_NE(test::read_file(f.dir + "/ramp.log").find("--cut-model forced"), std::string::npos) << test::read_file(f.dir + "/ramp.log");
}

}  // namespace
}  // namespace robodamp
