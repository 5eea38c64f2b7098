// Commissioning across the workspace (docs/pose_dynamics.md, "Measuring across the workspace"): `measure
// --poses` on a robot no preset describes, `identify all` on one pose's directory written elsewhere, `pose
// fit --measurements --hold-out` recovering the joints from the control-off measurements, and the refusals.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "config/config.hpp"
#include "config/file_paths.hpp"
#include "hil_files.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Child;

const std::string kSource = ROBODAMP_SOURCE_DIR;
const std::string kNominal = kSource + "/config/robots/planar_three_link.yaml";

struct Outcome {
  int status;
  std::string log;
};
Outcome robodamp(const std::vector<std::string>& args, const std::string& log) {
  Child c(args, log);
  const int status = c.wait();
  return {status, test::read_file(log)};
}

// A robot no preset describes: the planar model with joint 2 40 % stiffer and joint 3 27 % softer, in a
// directory of its own with a cell whose pose_schedule.model names it relative to the cell's file.
struct Workspace {
  std::string dir, cell, poses;
};
Workspace true_robot_cell(const std::string& name, double k2 = 5.6e5, double k3 = 2.9e3) {
  Workspace w;
  w.dir = ::testing::TempDir() + "/" + name;
  fs::remove_all(w.dir);
  fs::create_directories(w.dir);
  std::string robot = test::read_file(kNominal);
  test::replace_or_throw(robot, "stiffness_nm_per_rad: 4.05e5", "stiffness_nm_per_rad: " + std::to_string(k2));
  test::replace_or_throw(robot, "stiffness_nm_per_rad: 3.99e3", "stiffness_nm_per_rad: " + std::to_string(k3));
  std::ofstream(w.dir + "/true_robot.yaml") << robot;
  std::string cell = test::read_file(kSource + "/config/presets/pose_scheduled_c2.yaml");
  test::replace_or_throw(cell, "model: ../robots/planar_three_link.yaml", "model: true_robot.yaml");
  w.cell = w.dir + "/cell.yaml";
  std::ofstream(w.cell) << cell;
  // Written as a person would: a comment, block and flow styles mixed.
  w.poses = w.dir + "/poses.yaml";
  std::ofstream(w.poses)
      << "# where the robot was moved for the measurements\nposes:\n- name: p1\n  joints_deg: [-120, 130, -15]\n"
         "- {name: p2, joints_deg: [-100, 110, -20]}\n- {name: p3, joints_deg: [-85, 95, 10]}\n"
         "- {name: p4, joints_deg: [-110, 60, 30]}\n- {name: p5, joints_deg: [-95, 140, -40]}\n"
         "- {name: p6, joints_deg: [-70, 80, 0]}\n";
  return w;
}

TEST(PoseMeasurements, SixPosesMeasuredTheFittedModelFindsTheJointsAndPredictsTheHeldOutPeaks) {
  const Workspace w = true_robot_cell("pose_measurements");
  const std::string m = w.dir + "/measured";
  const Outcome measure =
      robodamp({"measure", "--config", w.cell, "--poses", w.poses, "--out", m}, w.dir + "/measure.log");
  ASSERT_EQ(measure.status, 0) << measure.log;
  const json index = json::parse(test::read_file(m + "/poses.json"));
  ASSERT_EQ(index["poses"].size(), 6U);
  for (const auto& p : index["poses"]) {
    EXPECT_EQ(p["status"], 0) << p.dump();
    const json manifest = json::parse(test::read_file(m + "/" + p["dir"].get<std::string>() + "/measurement.json"));
    EXPECT_EQ(manifest["pose"]["joints_deg"], p["joints_deg"]);
    EXPECT_EQ(manifest["pose"]["name"], p["name"]);
    EXPECT_EQ(fs::path(manifest["pose"]["robot_model"].get<std::string>()).filename(), "true_robot.yaml");
  }
  // Control off during each measurement: the recorded gain is 0 at every tick (a pose schedule's regions
  // carry gains of their own).
  const std::string csv = w.dir + "/p1.csv";
  ASSERT_EQ(robodamp({"csv", m + "/p1/loop.rdrec", "-o", csv}, w.dir + "/csv.log").status, 0);
  {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    std::size_t column = 0, ticks = 0, driven = 0;
    for (std::size_t at = 0, k = 0; at != std::string::npos; at = line.find(',', at + 1), ++k)
      if (line.compare(at == 0 ? 0 : at + 1, 14, "gain_ns_per_m,") == 0) column = k;
    ASSERT_GT(column, 0U) << line;
    while (std::getline(in, line)) {
      std::stringstream fields(line);
      std::string f;
      for (std::size_t k = 0; k <= column; ++k) std::getline(fields, f, ',');
      ++ticks;
      driven += std::stod(f) != 0.0 ? 1 : 0;
    }
    EXPECT_GT(ticks, 100000U);
    EXPECT_EQ(driven, 0U) << "ticks with a gain during the measurement";
  }
  // identify all's configuration, written in another directory, still finds the robot model.
  const std::string identified = ::testing::TempDir() + "/pose_measurements_p1.yaml";
  const Outcome id = robodamp({"identify", "all", "--in", m + "/p1", "--out", identified}, w.dir + "/identify.log");
  ASSERT_EQ(id.status, 0) << id.log;
  const config::Config c = config::load_config_file(identified);
  ASSERT_TRUE(c.pose_schedule.has_value());
  EXPECT_TRUE(fs::equivalent(c.pose_schedule->model_resolved, w.dir + "/true_robot.yaml"));

  const std::string fit = w.dir + "/fit.json";
  const Outcome f = robodamp({"pose", "fit", "--model", kNominal, "--measurements", m, "--hold-out", "p4", "p5", "p6",
                              "--restarts", "2", "--json", fit},  // seeds 1 and 2 (3, the default, finds the same)
                             w.dir + "/fit.log");
  ASSERT_EQ(f.status, 0) << f.log;
  const json r = json::parse(test::read_file(fit));
  EXPECT_EQ(r["direction"], "xx");  // the cell's pose_schedule.axis
  EXPECT_EQ(r["modes"], 3);         // the plant's form: the cell's pose_schedule.modes
  // The joints the measurements see (measured: 0.03 %, 0.05 %, 0.003 % off).
  EXPECT_NEAR(r["joints"][0]["stiffness_nm_per_rad"].get<double>() / 2.25e6, 1.0, 0.01) << f.log;
  EXPECT_NEAR(r["joints"][1]["stiffness_nm_per_rad"].get<double>() / 5.6e5, 1.0, 0.01) << f.log;
  EXPECT_NEAR(r["joints"][2]["stiffness_nm_per_rad"].get<double>() / 2.9e3, 1.0, 0.01) << f.log;
  int held = 0;
  for (const auto& p : r["poses"]) {
    const double measured = p["peak_hz"], nominal = p["nominal_peak_hz"], fitted = p["fitted_peak_hz"];
    EXPECT_LT(p["error_pct"].get<double>(), p["nominal_error_pct"].get<double>()) << p.dump();
    if (p["role"] != "held out") continue;
    ++held;
    EXPECT_NEAR(fitted, measured, 0.1) << p.dump();            // measured: within 0.01 Hz
    EXPECT_LT(p["error_pct"].get<double>(), 5.0) << p.dump();  // measured: 0.4-1.6 % (the model file: 106-122 %)
    EXPECT_LT(std::abs(fitted - measured), std::abs(nominal - measured) + 0.05) << p.dump();
  }
  EXPECT_EQ(held, 3);
}

TEST(PoseMeasurements, BadPosesAndMeasurementsAreRefusedWithThePoseAndTheReason) {
  const Workspace w = true_robot_cell("pose_refusals");
  // A pose outside joint 2's travel (0-170 deg).
  Outcome r = robodamp({"measure", "--config", w.cell, "--pose", "-100", "175", "0", "--out", w.dir + "/out"},
                       w.dir + "/a.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find("[-100, 175, 0] deg: joint 2 = 175 deg is out of range"), std::string::npos) << r.log;
  EXPECT_FALSE(fs::exists(w.dir + "/out/measurement.json"));
  // A poses file with a wrong count and a repeated name: nothing measured.
  std::ofstream(w.dir + "/bad_poses.yaml")
      << "poses:\n  - {name: a, joints_deg: [-100, 100, 0]}\n"
         "  - {name: b, joints_deg: [-100, 100, 0, 5]}\n  - {name: a, joints_deg: [-90, 90, 0]}\n";
  r = robodamp({"measure", "--config", w.cell, "--poses", w.dir + "/bad_poses.yaml", "--out", w.dir + "/many"},
               w.dir + "/b.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find("poses[1].joints_deg: a pose needs 3 joint angles"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("poses[2].name: 'a' names two poses"), std::string::npos) << r.log;
  EXPECT_FALSE(fs::exists(w.dir + "/many/a"));
  // --poses on hardware: nothing moves the robot between the measurements.
  r = robodamp(
      {"measure", "--config", kSource + "/config/hil_horizontal_c2.yaml", "--poses", w.poses, "--out", w.dir + "/hw"},
      w.dir + "/hw.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find("only the simulated plant can follow"), std::string::npos) << r.log;
  // A measurement without joint angles.
  r = robodamp({"measure", "--config", kSource + "/config/presets/horizontal_c2.yaml", "--out", w.dir + "/plain"},
               w.dir + "/c.log");
  ASSERT_EQ(r.status, 0) << r.log;
  r = robodamp({"pose", "fit", "--measurements", w.dir + "/plain"}, w.dir + "/d.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find(w.dir + "/plain: its measurement.json holds no joint angles"), std::string::npos) << r.log;
  // Two measurements at one pose that contradict each other: the same pose on this robot and on one
  // whose joint 2 is half as stiff.
  const Workspace soft = true_robot_cell("pose_refusals_soft", 2.8e5);
  const std::vector<std::string> at{"--pose", "-100", "110", "-20"};
  std::vector<std::string> a1{"measure", "--config", w.cell, "--out", w.dir + "/here"},
      a2{"measure", "--config", soft.cell, "--out", soft.dir + "/there"};
  a1.insert(a1.end(), at.begin(), at.end());
  a2.insert(a2.end(), at.begin(), at.end());
  ASSERT_EQ(robodamp(a1, w.dir + "/e.log").status, 0);
  ASSERT_EQ(robodamp(a2, w.dir + "/f.log").status, 0);
  // Measured against two robot model files: refused as such first.
  r = robodamp({"pose", "fit", "--measurements", w.dir + "/here", soft.dir + "/there"}, w.dir + "/g.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find("one model's joints, one set of measurements"), std::string::npos) << r.log;
  // As if both had named one model file (the soft robot's measurement relabelled): the contradiction is
  // the data's.
  fs::rename(soft.dir + "/there", soft.dir + "/there_soft");
  std::string manifest = test::read_file(soft.dir + "/there_soft/measurement.json");
  auto model_of = [](const std::string& dir) {
    return (fs::path(dir) / "true_robot.yaml").lexically_normal().string();
  };
  test::replace_or_throw(manifest, model_of(soft.dir), model_of(w.dir));
  std::ofstream(soft.dir + "/there_soft/measurement.json") << manifest;
  r = robodamp({"pose", "fit", "--measurements", w.dir + "/here", soft.dir + "/there_soft"}, w.dir + "/h.log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.log.find("were measured at the same pose [-100, 110, -20] deg and their FRFs differ by"),
            std::string::npos)
      << r.log;
  EXPECT_NE(r.log.find("contradicting data"), std::string::npos) << r.log;
  // Two poses, not one: the soft robot's measurement labelled 1.5 deg away along joint 3 (a pose read
  // wrong). The models put 15 % (nominal) and 33 % (the cell's) between the two poses' FRFs, the data 106 %:
  // refused by fit and by pose tune, naming both poses, and nothing written.
  test::replace_or_throw(manifest, "-20.0", "-18.5");
  std::ofstream(soft.dir + "/there_soft/measurement.json") << manifest;
  for (const std::vector<std::string>& cmd :
       {std::vector<std::string>{"pose", "fit", "--model", kNominal, "--measurements", w.dir + "/here",
                                 soft.dir + "/there_soft"},
        std::vector<std::string>{"pose", "tune", "--config", w.cell, "--measurements", w.dir + "/here",
                                 soft.dir + "/there_soft", "--out", w.dir + "/never.yaml"}}) {
    r = robodamp(cmd, w.dir + "/i.log");
    EXPECT_EQ(r.status, 2) << r.log;
    EXPECT_NE(r.log.find("[-100, 110, -18.5] deg) and " + w.dir + "/here (pose "), std::string::npos) << r.log;
    EXPECT_NE(r.log.find(" % the robot model "), std::string::npos) << r.log;
    EXPECT_NE(r.log.find("contradicting data"), std::string::npos) << r.log;
    EXPECT_FALSE(fs::exists(w.dir + "/never.yaml"));
  }
}

// A configuration moved to another directory names the same files: relative paths rebased, absolute ones
// and the rest of the text (comments, flow style) kept; a relative path not beside the configuration (found
// in the data folders, config/file_paths.hpp, from the new place as from the old) kept as written.
TEST(ConfigFilePaths, AMovedConfigurationStillNamesTheSameFiles) {
  const test::ScratchDir s("rebase");
  const std::string a = s.path;
  fs::create_directories(a + "/b/robots");
  fs::create_directories(a + "/b/cells/sets");
  std::ofstream(a + "/b/robots/r.yaml") << "# a robot\n";
  std::ofstream(a + "/b/cells/sets/h.yaml") << "# a set\n";
  const std::string text =
      "# the cell\npose_schedule: {model: ../robots/r.yaml, axis: x}  # flow\nspindle:\n  job: /abs/job.yaml\n"
      "parameter_sets:\n  horizontal: sets/h.yaml\n";
  const config::EditedYaml e = config::rebase_file_paths(text, a + "/b/cells/cell.yaml", a + "/out/deep/cell.yaml");
  EXPECT_TRUE(e.comments_kept);
  EXPECT_NE(e.text.find("# the cell"), std::string::npos) << e.text;
  EXPECT_NE(e.text.find("model: ../../b/robots/r.yaml"), std::string::npos) << e.text;
  EXPECT_NE(e.text.find("job: /abs/job.yaml"), std::string::npos) << e.text;
  EXPECT_NE(e.text.find("horizontal: ../../b/cells/sets/h.yaml"), std::string::npos) << e.text;
  EXPECT_EQ(config::rebase_file_paths(text, a + "/b/cells/cell.yaml", a + "/b/cells/other.yaml").text, text);
  const std::string shipped = "spindle:\n  job: ../milling/active_damping_c2.yaml\n";
  EXPECT_EQ(config::rebase_file_paths(shipped, a + "/b/cells/cell.yaml", a + "/out/deep/cell.yaml").text, shipped);
  // Bare file names (tune --out tuned.yaml in the working directory) are in the working directory.
  const fs::path was = fs::current_path();
  fs::current_path(a + "/b/cells");
  const std::string cwd = fs::current_path().lexically_normal().string();
  const std::string sub = config::rebase_file_paths(text, "cell.yaml", cwd + "/sub/tuned.yaml").text;
  const std::string same = config::rebase_file_paths(text, "cell.yaml", "tuned.yaml").text;
  fs::current_path(was);
  EXPECT_NE(sub.find("model: ../../robots/r.yaml"), std::string::npos) << sub;
  EXPECT_EQ(same, text);
}

}  // namespace
}  // namespace robodamp
