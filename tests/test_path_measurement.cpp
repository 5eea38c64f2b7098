// The commissioning measurement along the robot's path (commission/path_measurement.hpp, docs/pose_dynamics.md
// "Measuring along the path"): the HIL emulator moves the robot through two stops and hammers at each; the
// controller finds the stops from the joint registers and plays its chirp at each, with no pose typed. Each
// stop's directory identifies as a stopped measurement at that pose does.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "child_process.hpp"
#include "commission/dwell_watch.hpp"
#include "hil_files.hpp"
#include "identify/commissioning.hpp"
#include "identify/pose_measurements.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using nlohmann::json;
using test::Child;

// A short plan: settle 3 s, 3 chirp periods of 6 s, 2 s quiet, 3 impacts of 4 s at each of the 2 locations:
// 54 s from the robot's stop to the last record.
constexpr const char* kPlan =
    "\ncommissioning: {settle_s: 3, chirp_periods: 3, chirp_period_s: 6, quiet_s: 2, impacts_per_location: 3, "
    "record_s: 4}\n";

// The same cell without its wires (can, modbus, hil, dds): the simulated plant in process, for the stopped
// measurements at the same poses.
std::string stopped_config(const test::HilFiles& f) {
  YAML::Node n = YAML::LoadFile(f.config);
  for (const char* key : {"can", "modbus", "hil", "dds"}) n.remove(key);
  const std::string path = f.dir + "/stopped.yaml";
  std::ofstream(path) << YAML::Dump(n) << '\n';
  return path;
}

identify::CommissioningResult identified(const std::string& dir) {
  identify::CommissioningSettings s;
  return identify::identify_all(dir, s);
}

// Every FRF's modes: the same count, each frequency within 1 % and damping within 10 % of the stopped ones.
void expect_same_modes(const identify::CommissioningResult& along, const identify::CommissioningResult& stopped,
                       const std::string& what) {
  ASSERT_EQ(along.frfs.size(), stopped.frfs.size()) << what;
  for (std::size_t i = 0; i < along.frfs.size(); ++i) {
    const auto& a = along.frfs[i].fit.modes;
    const auto& b = stopped.frfs[i].fit.modes;
    ASSERT_EQ(a.size(), b.size()) << what << " " << along.frfs[i].name;
    for (std::size_t k = 0; k < a.size(); ++k) {
      std::cout << what << " " << along.frfs[i].name << " mode " << k + 1 << ": " << a[k].natural_freq_hz
                << " Hz, zeta " << a[k].damping_ratio << " (stopped: " << b[k].natural_freq_hz << " Hz, "
                << b[k].damping_ratio << ")\n";
      EXPECT_NEAR(a[k].natural_freq_hz, b[k].natural_freq_hz, 0.01 * b[k].natural_freq_hz) << what << " mode " << k + 1;
      EXPECT_NEAR(a[k].damping_ratio, b[k].damping_ratio, 0.1 * b[k].damping_ratio) << what << " mode " << k + 1;
    }
  }
  EXPECT_NEAR(along.dominant_mode_hz, stopped.dominant_mode_hz, 0.01 * stopped.dominant_mode_hz) << what;
  EXPECT_NEAR(along.actuator.natural_freq_hz, stopped.actuator.natural_freq_hz, 0.01 * stopped.actuator.natural_freq_hz)
      << what;
}

TEST(PathMeasurement, TheRobotStopsTwiceEachStopIdentifiesAsAStoppedMeasurementThere) {
  const test::HilFiles f = test::hil_files("along_path", {}, "hil_pose_schedule");
  std::ofstream(f.config, std::ios::app) << kPlan;
  const std::vector<std::vector<double>> poses{{-100, 20, 90}, {-100, 100, 90}};
  const std::string dir = f.dir + "/path";
  {
    Child plant({"plant", "--config", f.config, "--pacing", "lockstep", "--measure-out", dir, "--json", f.plant_json,
                 "--pose-at", "0:-100,20,90", "--pose-at", "57:-100,20,90", "--pose-at", "63:-100,100,90", "--pose-at",
                 "120:-100,100,90"},
                f.plant_log);
    Child measure({"measure", "--config", f.config, "--out", dir, "--clock", "virtual", "--along-path", "--dwells", "2",
                   "--duration", "200"},
                  f.run_log);
    ASSERT_EQ(measure.wait(), 0) << test::read_file(f.run_log);
    ASSERT_EQ(plant.wait(), 0) << test::read_file(f.plant_log);
  }
  const std::string log = test::read_file(f.run_log);
  EXPECT_NE(log.find("2 of 2 dwells measured along the path"), std::string::npos) << log;
  const json index = json::parse(test::read_file(dir + "/poses.json"));
  ASSERT_EQ(index.at("poses").size(), 2U) << index.dump(2);
  const std::string stopped = stopped_config(f);
  // Each measured stop in the index with its folder, numbered as the emulator numbers its stops. On a loaded
  // machine the joints, polled on the wall clock while the loop runs on the virtual one, can look still during
  // the move between the stops (the CI run at 6e17f3f named the second stop dwell_4 while the hammer's FRFs were
  // in dwell_2): such a pause is shorter than commissioning.settle_s, logged, and takes no number.
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const json& p = index["poses"][i];
    const std::string name = p.at("dir").get<std::string>();
    EXPECT_EQ(name, "dwell_" + std::to_string(i + 1)) << index.dump(2) << log;
    for (std::size_t j = 0; j < 3; ++j)  // read from the registers (0.01 deg per count)
      EXPECT_NEAR(p.at("joints_deg")[j].get<double>(), poses[i][j], 0.006) << i << " joint " << j + 1;
    const std::string at = dir + "/" + name;
    // The shared recording replays bit for bit, the on-command chirps included.
    Child replay({"replay", at + "/" + identify::kRecordingName}, f.dir + "/replay.log");
    ASSERT_EQ(replay.wait(), 0) << test::read_file(f.dir + "/replay.log");
    EXPECT_NE(test::read_file(f.dir + "/replay.log").find("bit for bit"), std::string::npos);
    // The same pose measured standing still, in process.
    std::vector<std::string> args{"measure", "--config", stopped, "--out", f.dir + "/stopped_" + std::to_string(i + 1),
                                  "--pose"};
    for (double q : poses[i]) args.push_back(std::to_string(q));
    Child still(args, f.dir + "/stopped.log");
    ASSERT_EQ(still.wait(), 0) << test::read_file(f.dir + "/stopped.log");
    expect_same_modes(identified(at), identified(f.dir + "/stopped_" + std::to_string(i + 1)),
                      "dwell " + std::to_string(i + 1));
  }
  // The index is what pose fit and pose modes read (--measurements DIR): both stops, at the joints read.
  const identify::PoseMeasurements pm = identify::read_pose_measurements({dir});
  ASSERT_EQ(pm.frfs.size(), 2U);
  EXPECT_EQ(pm.frfs[1].name, index["poses"][1].at("dir").get<std::string>());
  EXPECT_NEAR(pm.frfs[1].joints_deg[1], 100.0, 0.006);
  std::filesystem::remove_all(f.dir);
}

// A robot whose joints are a function of loop time, and a loop that starts the chirp the tick after it is
// asked to: the dwell watch driven frame by frame, no processes.
struct ScriptedRobot final : commission::DwellCell {
  std::vector<double> (*pose_at)(double){nullptr};
  double now_s{0.0};
  bool start_posted{false}, stop_requested{false};
  [[nodiscard]] std::vector<double> robot_pose_deg() const override { return pose_at(now_s); }
  [[nodiscard]] bool post(const rt::OperatorCommand& c) override {
    start_posted = start_posted || c.kind == rt::CommandKind::kStartExcitation;
    return true;
  }
  void request_stop() noexcept override { stop_requested = true; }
};

commission::DwellWatch watched(ScriptedRobot& robot, double run_s, int dwells) {
  config::Config cfg;
  cfg.loop.rate_hz = 1000.0;
  cfg.commissioning.settle_s = 3.0, cfg.commissioning.chirp_period_s = 6.0, cfg.commissioning.chirp_periods = 3;
  analysis::CommissioningPlan plan;
  plan.duration_s = 54.0;
  commission::PathMeasureOptions o;
  o.dwells = dwells;
  commission::DwellWatch watch(cfg, plan, o);
  watch.attach(&robot);
  rt::TelemetryFrame f;
  f.state = static_cast<std::uint8_t>(rt::State::kActive);
  for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(run_s * cfg.loop.rate_hz) && !robot.stop_requested; ++k) {
    f.tick = k, f.time_s = static_cast<double>(k) / cfg.loop.rate_hz, robot.now_s = f.time_s;
    f.command_kind =
        static_cast<std::uint8_t>(robot.start_posted ? rt::CommandKind::kStartExcitation : rt::CommandKind::kNone);
    robot.start_posted = false;
    watch.on_frame(f);
  }
  return watch;
}

// The CI run at 6e17f3f: the joints' readings stood still for a moment during the move between two stops, the
// watch numbered that a dwell, and the second stop became dwell_4 while the hammer's FRFs were in dwell_2. A
// stillness shorter than commissioning.settle_s is a pause: no number; a stop the robot leaves during the chirp
// keeps its number (the plant side hammers there) and is skipped with its reason.
TEST(PathMeasurement, APauseShorterThanTheSettlingTimeTakesNoDwellNumber) {
  ScriptedRobot robot;
  robot.pose_at = [](double t) -> std::vector<double> {
    if (t < 60.0) return {-100, 20, 90};
    if (t < 66.0) {
      const double s = t >= 62.0 && t < 63.5 ? 62.0 : t;  // the reading stands for 1.5 s mid-move
      return {-100, 20 + 80 * (s - 60.0) / 6.0, 90};
    }
    if (t < 126.0) return {-100, 100, 90};
    if (t < 127.0) return {-100, 100 - (t - 126.0), 90};
    if (t < 137.0) return {-100, 99, 90};  // leaves during the chirp (from 130 s)
    return {-100, 99 - (t - 137.0), 90};
  };
  const commission::DwellWatch watch = watched(robot, 150.0, 3);
  const auto& d = watch.dwells();
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(watch.pauses(), 1);
  EXPECT_EQ(d[0].name, "dwell_1");
  EXPECT_EQ(d[1].name, "dwell_2");
  EXPECT_EQ(d[2].name, "dwell_3");
  EXPECT_TRUE(d[0].measured && d[1].measured);
  EXPECT_NEAR(d[1].joints_deg[1], 100.0, 1e-9);
  EXPECT_NEAR(d[1].still_s, 66.0, 0.02);
  EXPECT_NEAR(d[1].chirp_start_s, 69.0, 0.02);  // settle_s after the stop
  EXPECT_FALSE(d[2].measured);
  EXPECT_NE(d[2].skipped.find("during the chirp"), std::string::npos) << d[2].skipped;
  EXPECT_FALSE(robot.stop_requested);  // 2 of 3 measured: the run goes on
}

TEST(PathMeasurement, NoJointsToFollowAndStopsTooShortAreRefusedByName) {
  const test::HilFiles f = test::hil_files("along_path_refused", {}, "hil_pose_schedule");
  std::ofstream(f.config, std::ios::app) << kPlan;
  // The simulated plant in process reports no joints: nothing to follow.
  Child sim({"measure", "--config", test::preset("pose_scheduled_c2"), "--out", f.dir + "/sim", "--along-path"},
            f.dir + "/sim.log");
  EXPECT_EQ(sim.wait(), 2);
  EXPECT_NE(test::read_file(f.dir + "/sim.log").find("follows a robot that reports its joints"), std::string::npos)
      << test::read_file(f.dir + "/sim.log");
  Child both({"measure", "--config", f.config, "--out", f.dir + "/both", "--along-path", "--pose", "-100", "20", "90"},
             f.dir + "/both.log");
  EXPECT_NE(both.wait(), 0);
  // A stop shorter than the plan (54 s) on the plant side: refused before any controller is served.
  Child plant({"plant", "--config", f.config, "--pacing", "lockstep", "--measure-out", f.dir + "/short", "--pose-at",
               "0:-100,20,90", "--pose-at", "30:-100,20,90"},
              f.plant_log);
  EXPECT_EQ(plant.wait(), 2);
  EXPECT_NE(test::read_file(f.plant_log)
                .find("dwell 1 at [-100, 20, 90] deg lasts 30 s: the commissioning measurement at "
                      "a stop needs 54 s"),
            std::string::npos)
      << test::read_file(f.plant_log);
  std::filesystem::remove_all(f.dir);
}

}  // namespace
}  // namespace robodamp
