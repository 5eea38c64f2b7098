// `robodamp pose modes` end to end (docs/pose_dynamics.md, "Modes between measured poses"): a robot whose
// model is wrong in form measured at six poses of the HIL path (`measure --poses`), its model fitted on three
// (`pose fit`), the modes measured at those three written into the fitted model (`pose modes --out`) and
// checked at the three held out; the mapped modes at a pose shown with their uncertainty; the refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kSource = ROBODAMP_SOURCE_DIR;

struct Outcome {
  int status;
  std::string log;
};
Outcome robodamp(const std::vector<std::string>& args, const std::string& log) {
  test::Child c(args, log);
  const int status = c.wait();
  return {status, test::read_file(log)};
}

TEST(PoseModes, ARobotWrongInFormIsMappedFromItsMeasuredPosesAndMeetsTheHeldOutOnesWithinTwoPercent) {
  const test::ScratchDir dir("pose_modes");
  const std::string d = dir.path;
  // The truth: the compact arm with an elbow whose bearings give in translation (6e5 N/m), a compliance the
  // model file's torsional joints cannot represent.
  std::string robot = test::read_file(kSource + "/config/robots/compact_three_link.yaml");
  test::replace_or_throw(robot, "{stiffness_nm_per_rad: 2.2e5, damping_ratio: 0.02, min_deg: 10, max_deg: 160}",
                         "{stiffness_nm_per_rad: 2.2e5, damping_ratio: 0.02, min_deg: 10, max_deg: 160, "
                         "translational_stiffness_n_per_m: 6e5}");
  std::ofstream(d + "/true_robot.yaml") << robot;
  // The HIL cell on the simulated plant (no CAN, no Modbus), its workspace the compact arm's path.
  std::string cell = test::read_file(kSource + "/config/hil_pose_schedule.yaml");
  cell = cell.substr(0, cell.find("\ncan:")) + cell.substr(cell.find("\nhil:"));
  test::replace_or_throw(cell, "model: robots/planar_three_link.yaml", "model: true_robot.yaml");
  test::replace_or_throw(cell, "workspace: {min_deg: [-102, 0, 88], max_deg: [-98, 140, 92]}",
                         "workspace: {min_deg: [-90.5, 30, 29], max_deg: [-89.5, 130, 31]}");
  test::replace_or_throw(cell, "{name: folded, min_deg: [-102, 0, 88], max_deg: [-98, 25, 92], gain_ns_per_m: 250}",
                         "{name: folded, min_deg: [-90.5, 30, 29], max_deg: [-89.5, 62, 31], gain_ns_per_m: 100}");
  test::replace_or_throw(cell,
                         "{name: stretched, min_deg: [-102, 20, 88], max_deg: [-98, 140, 92], gain_ns_per_m: 200}",
                         "{name: stretched, min_deg: [-90.5, 58, 29], max_deg: [-89.5, 130, 31], gain_ns_per_m: 100}");
  std::ofstream(d + "/cell.yaml") << cell;
  // Five poses for the map (about 20-30 deg apart) and three between them held out, written as a person would.
  std::ofstream(d + "/poses.yaml")
      << "poses:\n  - {name: a, joints_deg: [-90, 30, 30]}\n  - {name: b, joints_deg: [-90, 50, 29.5]}\n"
         "  - name: c\n    joints_deg: [-90, 65, 30.5]\n  - {name: g, joints_deg: [-90, 80, 30]}\n"
         "  - {name: d, joints_deg: [-90, 90, 30]}\n  - {name: h, joints_deg: [-90, 100, 30]}\n"
         "  - {name: e, joints_deg: [-90.25, 110, 29.5]}\n  - {name: f, joints_deg: [-90, 130, 30]}\n";
  const Outcome measure = robodamp(
      {"measure", "--config", d + "/cell.yaml", "--poses", d + "/poses.yaml", "--out", d + "/m"}, d + "/measure.log");
  ASSERT_EQ(measure.status, 0) << measure.log;
  const Outcome fit =
      robodamp({"pose", "fit", "--model", kSource + "/config/robots/compact_three_link.yaml", "--measurements",
                d + "/m", "--hold-out", "b", "d", "e", "--restarts", "1", "--out", d + "/fitted.yaml"},
               d + "/fit.log");
  ASSERT_EQ(fit.status, 0) << fit.log;
  const Outcome map = robodamp({"pose", "modes", "--model", d + "/fitted.yaml", "--measurements", d + "/m",
                                "--hold-out", "b", "d", "e", "--out", d + "/mapped.yaml", "--json", d + "/modes.json"},
                               d + "/modes.log");
  ASSERT_EQ(map.status, 0) << map.log;
  std::cout << map.log;
  const json r = json::parse(test::read_file(d + "/modes.json"));
  const double model_error = r["held_out_worst_freq_error_pct"]["model"],
               mapped_error = r["held_out_worst_freq_error_pct"]["mapped"];
  // Every held-out mode found by the map within 2 %; the fitted model misses some or is further off.
  EXPECT_LT(mapped_error, 2.0);
  EXPECT_EQ(r["held_out_modes_missed"]["mapped"].get<int>(), 0);
  EXPECT_TRUE(model_error > mapped_error || r["held_out_modes_missed"]["model"].get<int>() > 0);
  // Every measured mode at a held-out pose found by the map, its uncertainty larger than at the map's poses.
  int held_rows = 0;
  for (const auto& row : r["rows"]) {
    ASSERT_FALSE(row["mapped_hz"].is_null()) << row.dump();
    if (row["role"] == "held out") ++held_rows;
  }
  EXPECT_GE(held_rows, 3);
  // The written model reads back with its measured modes; at a held-out pose it shows the modes with their spread.
  const std::string mapped = test::read_file(d + "/mapped.yaml");
  EXPECT_NE(mapped.find("measured_modes:"), std::string::npos);
  const Outcome show = robodamp(
      {"pose", "modes", "--model", d + "/mapped.yaml", "--joints", "-90", "90", "30", "--json", d + "/show.json"},
      d + "/show.log");
  ASSERT_EQ(show.status, 0) << show.log;
  const json s = json::parse(test::read_file(d + "/show.json"));
  EXPECT_NEAR(s["nearest_measured_deg"].get<double>(), 10.0, 0.1);
  int measured = 0;
  for (const auto& m : s["modes"])
    if (m["measured_poses"].get<int>() > 0) {
      ++measured;
      EXPECT_GT(m["freq_sigma_pct"].get<double>(), 0.0);
    }
  EXPECT_EQ(measured, 3);
  // The plot along joint 2 (the others at the pose shown): each mapped mode's line passes through the modes
  // measured at the map's poses, and beside it the model's mode it follows, none for a mode the measurements
  // alone give (the plot paired a fitted model's 1 Hz mode with the measured 9 Hz one before 2026-12-06).
  const Outcome plot = robodamp({"pose", "modes", "--model", d + "/mapped.yaml", "--joints", "-90", "90", "30",
                                 "--plot-dir", d + "/plots", "--vary", "2", "--json", d + "/sweep.json"},
                                d + "/plot.log");
  ASSERT_EQ(plot.status, 0) << plot.log;
  EXPECT_GT(std::filesystem::file_size(d + "/plots/pose_modes.png"), 10000U);
  const json points = json::parse(test::read_file(d + "/sweep.json"))["sweep"]["points"];
  ASSERT_EQ(points.size(), 121U);
  for (const auto& p : points)
    for (std::size_t k = 0; k < s["modes"].size(); ++k)
      EXPECT_EQ(p["model_hz"][k].is_null(), s["modes"][k]["measured_only"].get<bool>()) << k << " " << p.dump();
  int on_line = 0;
  for (const auto& row : r["rows"]) {
    if (row["role"] != "map") continue;
    const double q2 = row["joints_deg"][1], f = row["measured_hz"];
    const json* nearest = &points[0];
    for (const auto& p : points)
      if (std::abs(p["joint_deg"].get<double>() - q2) < std::abs((*nearest)["joint_deg"].get<double>() - q2))
        nearest = &p;
    double best = 1e9;
    for (const auto& m : (*nearest)["mapped_hz"]) best = std::min(best, std::abs(m.get<double>() / f - 1.0));
    EXPECT_LT(best, 0.01) << row.dump() << (*nearest).dump();
    ++on_line;
  }
  EXPECT_EQ(on_line, 15);  // 5 poses x 3 modes
  // A cell on the mapped model says the spread at the robot's pose (the machining topic, the monitor, the run
  // summary): the largest frequency sigma of its modes there, and how far the nearest measured pose is.
  std::string job = test::read_file(kSource + "/config/milling/planar_three_link_wall_x.yaml");
  test::replace_or_throw(job, "model: ../robots/", "model: " + kSource + "/config/robots/");
  std::ofstream(d + "/job.yaml") << job;
  std::string on_map = cell;
  test::replace_or_throw(on_map, "model: true_robot.yaml", "model: mapped.yaml");
  std::ofstream(d + "/cell_mapped.yaml") << on_map << "\nspindle:\n  teeth: 3\n  job: job.yaml\n";
  // (The stretched region's set is handed over from region 0's at the start: armed after about 4 s.)
  const Outcome run =
      robodamp({"run", "--config", d + "/cell_mapped.yaml", "--pose", "-90", "90", "30", "--spindle-rpm", "700",
                "--clock", "virtual", "--duration", "8", "--json", d + "/run.json"},
               d + "/run.log");
  ASSERT_EQ(run.status, 0) << run.log;
  const json machining = json::parse(test::read_file(d + "/run.json"))["machining"];
  double widest = 0.0;
  for (const auto& m : s["modes"]) widest = std::max(widest, m["freq_sigma_pct"].get<double>());
  ASSERT_TRUE(machining.contains("mode_spread_pct")) << machining.dump();
  EXPECT_NEAR(machining["mode_spread_pct"].get<double>(), widest, 1e-9 * widest) << machining.dump();
  EXPECT_NEAR(machining["nearest_measured_deg"].get<double>(), 10.0, 0.1) << machining.dump();
  EXPECT_NE(run.log.find("its modes there from the measured map: +-"), std::string::npos) << run.log;
  // Refused: a model with no measured modes to show, and --out without --measurements.
  const Outcome none =
      robodamp({"pose", "modes", "--model", d + "/fitted.yaml", "--joints", "-90", "90", "30"}, d + "/none.log");
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.log.find("has no measured modes"), std::string::npos) << none.log;
  const Outcome out =
      robodamp({"pose", "modes", "--model", d + "/mapped.yaml", "--out", d + "/x.yaml"}, d + "/out.log");
  EXPECT_EQ(out.status, 2);
  EXPECT_NE(out.log.find("--out and --hold-out go with --measurements"), std::string::npos) << out.log;
}

}  // namespace
}  // namespace robodamp
