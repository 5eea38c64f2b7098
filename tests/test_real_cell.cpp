// Commissioning a real cell (docs/identification.md, "Commissioning a real cell"): the actuator's chirp
// alone, the user's tap tests read and checked against it, the measurement's safety watch (not at rest,
// saturation, the operator's abort), the plan printed by --dry-run, and the margins read from a loop on a
// grid. The whole commissioning through the HIL emulator told it is real: tests/test_commission_hil.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "modal_kit.hpp"
#include "commission/measurement.hpp"
#include "commission/real_cell_check.hpp"
#include "identify/tap_tests.hpp"
#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"
#include "test_util.hpp"
#include "units/units.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;

const std::string kRobotA = std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/robot_a_two_modes.yaml";

// Robot A with its YAML edited (each text replaced once, `extra` appended), written into dir.
std::string robot_a(const test::ScratchDir& dir, const std::string& name,
                    const std::vector<std::pair<std::string, std::string>>& edits, const std::string& extra = {}) {
  std::string text = test::read_file(kRobotA);
  for (const auto& [from, to] : edits) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  const std::string path = dir.file(name + ".yaml");
  std::ofstream(path) << text << '\n' << extra;
  return path;
}

// The modal kit's export of a simulated impact test of `robot` (tests/modal_kit.hpp), in dir.
std::string tap_test_export(const test::ScratchDir& dir, const std::string& robot, const std::string& name,
                            double calibration) {
  return test::modal_kit_export(robot, dir.file(name), dir.file(name + ".uff"), calibration);
}

struct Identified {
  identify::CommissioningInputs inputs;
  identify::TapTests taps;
  identify::CommissioningResult result;
  identify::TapTestConsistency check;
};

Identified identify_with(const std::string& chirp_dir, const std::vector<std::string>& taps) {
  Identified r;
  r.inputs = identify::inputs_with_tap_tests(chirp_dir, taps, r.taps);
  r.result = identify::identify_all(r.inputs, {});
  r.check = identify::check_tap_tests(r.inputs, r.result, r.taps);
  return r;
}

std::string chirp_only(const test::ScratchDir& dir, const std::string& robot, const std::string& name) {
  commission::MeasureOptions o;
  o.impacts = false;
  const std::string out = dir.file(name);
  const commission::MeasureOutcome m = commission::measure(robot, out, o);
  EXPECT_EQ(m.status, commission::MeasureStatus::kOk) << m.message;
  EXPECT_EQ(m.impact_records, 0);
  EXPECT_FALSE(fs::exists(out + "/frf_1_1.csv"));  // no hammer
  // The actuator's FRF at the sensor, with its coherence, for a modal package: nothing else.
  const measfiles::UffFile u = measfiles::read_uff(out + "/" + identify::kMeasurementUffName);
  EXPECT_EQ(u.functions.size(), 2u);
  if (!u.functions.empty()) {
    EXPECT_EQ(u.functions[0].reference_entity, identify::kVoltageEntity);
  }
  return out;
}

TEST(RealCell, TapTestsOfTheSameRobotAgreeWithTheChirpAndAnotherRobotsAreRefused) {
  const test::ScratchDir dir("real-cell-taps");
  const std::string chirp = chirp_only(dir, kRobotA, "chirp");

  // The same robot, tapped with a 2 % calibration error: the modes agree, the actuator absorbs the scale.
  const Identified same = identify_with(chirp, {tap_test_export(dir, kRobotA, "same", 1.02)});
  EXPECT_EQ(same.check.failure(), "") << same.check.summary();
  ASSERT_EQ(same.check.modes.size(), 2u) << same.check.chirp_fit;
  for (const auto& m : same.check.modes) {
    ASSERT_TRUE(m.chirp_hz);
    EXPECT_LT(m.difference_pct, 0.5) << m.tap_hz;
  }
  EXPECT_NEAR(same.check.modes[0].tap_hz, 5.5, 0.055);
  EXPECT_NEAR(same.check.modes[1].tap_hz, 16.0, 0.16);
  EXPECT_LT(same.check.chirp_residual_pct, 5.0);
  // The 2 % shows in the actuator's constant: the tapped structure looks 2 % softer, so the same chirp reads as
  // an actuator 2 % weaker (6 N/V configured); the loop's gain, what the chirp measures, is unchanged.
  EXPECT_NEAR(same.result.actuator.force_constant_n_per_v, 6.0 / 1.02, 0.1);

  // Tapped on a robot whose modes sit 3 % higher (another pose, another tool): refused, naming the mode.
  std::vector<std::pair<std::string, std::string>> shift;
  for (int i = 0; i < 3; ++i)
    shift.emplace_back("natural_freq_hz: 5.5,", "natural_freq_hz: 5.665,"),
        shift.emplace_back("natural_freq_hz: 16.0,", "natural_freq_hz: 16.48,");
  const Identified other = identify_with(chirp, {tap_test_export(dir, robot_a(dir, "shifted", shift), "other", 1.0)});
  const std::string why = other.check.failure();
  EXPECT_NE(why.find("the tap tests contradict the actuator's chirp: their mode at 5.67 Hz is at 5.50 Hz"),
            std::string::npos)
      << why;
  EXPECT_GT(other.check.chirp_residual_pct, 3.0 * same.check.chirp_residual_pct)
      << other.check.summary() << " / " << same.check.summary();
}

// The same from the command line: identify all --in (the chirp) --tap-tests, whose output tune reads.
TEST(RealCell, IdentifyAllTakesTapTestsAndRefusesContradictingOnes) {
  const test::ScratchDir dir("real-cell-cli");
  const std::string chirp = chirp_only(dir, kRobotA, "chirp");
  const std::string taps = tap_test_export(dir, kRobotA, "kit", 1.0);
  const auto ok =
      test::run_robodamp("identify all --in " + chirp + " --tap-tests " + taps + " --out " + dir.file("id.yaml"));
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("the tap tests against the actuator's chirp: 5.500 Hz tapped"), std::string::npos) << ok.out;
  EXPECT_NEAR(config::load_config_file(dir.file("id.yaml")).robot.frfs.at(0).modes.at(1).natural_freq_hz, 16.0, 0.16);
  std::vector<std::pair<std::string, std::string>> shift;
  for (int i = 0; i < 3; ++i) shift.emplace_back("natural_freq_hz: 16.0,", "natural_freq_hz: 16.48,");
  const std::string other = tap_test_export(dir, robot_a(dir, "shifted", shift), "other", 1.0);
  const auto bad =
      test::run_robodamp("identify all --in " + chirp + " --tap-tests " + other + " --out " + dir.file("id2.yaml"));
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_NE(bad.out.find("the tap tests contradict the actuator's chirp: their mode at 16.48 Hz"), std::string::npos)
      << bad.out;
  EXPECT_FALSE(fs::exists(dir.file("id2.yaml")));
}

TEST(RealCell, TapTestsComeAsUniversalFilesOrFrfCsvsAndReciprocityIsChecked) {
  const test::ScratchDir dir("real-cell-csv");
  const std::string chirp = chirp_only(dir, kRobotA, "chirp");
  const std::string sim = dir.file("sim");
  ASSERT_EQ(commission::measure(kRobotA, sim).status, commission::MeasureStatus::kOk);
  // The three CSVs robodamp's own naming gives (H12 left out: H21 stands for the pair).
  const Identified csv = identify_with(chirp, {sim + "/frf_1_1.csv", sim + "/frf_2_1.csv", sim + "/frf_2_2.csv"});
  EXPECT_EQ(csv.check.failure(), "") << csv.check.summary();
  EXPECT_EQ(csv.taps.frfs.size(), 3u);
  EXPECT_TRUE(csv.taps.reciprocal.empty());

  // Both ways round: compared, and close (the simulated structure is reciprocal; each estimate has its noise).
  const Identified both =
      identify_with(chirp, {sim + "/frf_1_1.csv", sim + "/frf_2_1.csv", sim + "/frf_1_2.csv", sim + "/frf_2_2.csv"});
  ASSERT_EQ(both.check.reciprocity.size(), 1u);
  EXPECT_LT(both.check.reciprocity[0].difference_pct, 10.0);
  EXPECT_EQ(both.check.failure(), "");

  // One direction tapped with a wrong sensitivity (x 1.5): not reciprocal, refused.
  const std::string bad = dir.file("bad");
  fs::create_directories(bad);
  std::ifstream in(sim + "/frf_1_2.csv");
  std::ofstream out(bad + "/frf_1_2.csv");
  out.precision(9);
  for (std::string line; std::getline(in, line);) {
    double f = 0, re = 0, im = 0, coh = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &f, &re, &im, &coh) == 4)
      out << f << ',' << 1.5 * re << ',' << 1.5 * im << ',' << coh << '\n';
    else
      out << line << '\n';
  }
  out.close();
  const Identified wrong =
      identify_with(chirp, {sim + "/frf_1_1.csv", sim + "/frf_2_1.csv", bad + "/frf_1_2.csv", sim + "/frf_2_2.csv"});
  EXPECT_NE(wrong.check.failure().find("not reciprocal: H21yy and H12 differ by"), std::string::npos)
      << wrong.check.failure() << " / " << wrong.check.summary();

  // A pair nobody tapped, and a pair tapped twice, are refused by name.
  identify::TapTests t;
  try {
    (void)identify::inputs_with_tap_tests(chirp, {sim + "/frf_1_1.csv", sim + "/frf_2_2.csv"}, t);
    ADD_FAILURE() << "a missing pair was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no FRF between locations 2 and 1"), std::string::npos) << e.what();
  }
  try {
    (void)identify::inputs_with_tap_tests(
        chirp,
        {sim + "/frf_1_1.csv", sim + "/frf_2_1.csv", sim + "/frf_2_2.csv", sim + "/" + identify::kMeasurementUffName},
        t);
    ADD_FAILURE() << "a pair given twice was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("two tap tests from node 1 to node 1"), std::string::npos) << e.what();
  }
}

TEST(RealCell, TheChirpWaitsForACellAtRestAndStopsWhenItSaturates) {
  const test::ScratchDir dir("real-cell-safety");
  commission::MeasureOptions o;
  o.impacts = false;
  // The robot moving (3 m/s^2 of drive vibration): refused when the chirp is due, before it plays.
  const std::string moving = robot_a(dir, "moving", {{"drive_vibration_mps2: 0.01", "drive_vibration_mps2: 3.0"}});
  const commission::MeasureOutcome m = commission::measure(moving, dir.file("moving"), o);
  EXPECT_EQ(m.status, commission::MeasureStatus::kNotReady);
  EXPECT_NE(m.message.find("not ready: the cell is not at rest"), std::string::npos) << m.message;
  EXPECT_GT(m.rest_accel_rms_mps2, 1.0);
  // Stopped when the chirp was due (the watch on the drain thread: on the virtual clock the loop has run a
  // few ticks on by then), not after its 32 s.
  EXPECT_LT(m.recorded_frames, 5000u * 10u) << "the chirp played";
  EXPECT_EQ(commission::exit_code(m.status), 6);

  // A level that, with the controller on, drives the amplifier into its limit: stopped at the first such tick.
  const std::string hot = robot_a(dir, "hot", {{"voltage_limit_v: 10", "voltage_limit_v: 1.0"}},
                                  "commissioning: {chirp_force_fraction: 0.9}\n");
  o.control_on = true;
  const commission::MeasureOutcome s = commission::measure(hot, dir.file("hot"), o);
  EXPECT_EQ(s.status, commission::MeasureStatus::kSaturated);
  EXPECT_NE(s.message.find("the excitation saturates: the supervisor limited the command"), std::string::npos)
      << s.message;
  EXPECT_LT(s.chirp_active_share, 1.0);  // it did not play on
  EXPECT_EQ(commission::exit_code(s.status), 7);
  // The same level with control off stays inside the limit: measured.
  o.control_on = false;
  EXPECT_EQ(commission::measure(hot, dir.file("hot_off"), o).status, commission::MeasureStatus::kOk);
}

TEST(RealCell, TheOperatorAbortsAMeasurementWithCtrlC) {
  const test::ScratchDir dir("real-cell-abort");
  // A long chirp (2 x 600 s of loop time) so that the signal arrives while it plays.
  const std::string robot = robot_a(dir, "long", {}, "commissioning: {chirp_period_s: 600, chirp_periods: 2}\n");
  test::Child child({"measure", "--no-hammer", "--config", robot, "--out", dir.file("out")}, dir.file("measure.log"));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (test::read_file(dir.file("measure.log")).find("chirp period 1 of 2") == std::string::npos) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << test::read_file(dir.file("measure.log"));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  child.kill(SIGINT);
  const auto rc = child.wait_for(120.0);
  ASSERT_TRUE(rc);
  EXPECT_EQ(*rc, 8);
  const std::string log = test::read_file(dir.file("measure.log"));
  EXPECT_NE(log.find("aborted by the operator (signal 2)"), std::string::npos) << log;
  const auto j = nlohmann::json::parse(test::read_file(dir.file("out/measurement.json")));
  EXPECT_NE(j["run"]["refused"].get<std::string>().find("aborted"), std::string::npos);
}

TEST(RealCell, DryRunPrintsThePlanAndRunsNothing) {
  const test::ScratchDir dir("real-cell-dry");
  const auto r = test::run_robodamp("measure --dry-run --no-hammer --config " + kRobotA + " --out " + dir.file("out"));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("what moves: the inertial actuator's mass only; 4 periods of a 2.0-100.0 Hz chirp"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("predicted peak actuator force 20.0 N of its 40 N limit"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no hammer"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir.file("out")));
  std::ofstream(dir.file("taps.uff")) << "";  // a dry run reads no tap test
  const auto c = test::run_robodamp(
      "commission --dry-run --config " + kRobotA + " --job " + std::string(ROBODAMP_SOURCE_DIR) +
      "/config/commissioning/job_a_two_modes.yaml --out " + dir.file("c") + " --tap-tests " + dir.file("taps.uff"));
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("the same chirp with the tuned controller running (control ON), no hammer, no cut"),
            std::string::npos)
      << c.out;
  EXPECT_FALSE(fs::exists(dir.file("c")));
}

// L = (wc / jw) e^{-jw tau}: |L| = 1 at wc, PM = 90 deg - wc tau; the phase reaches -180 deg at w = pi / (2 tau),
// GM = -20 log10(wc / w180).
TEST(RealCell, MarginsOnAGridAreThoseOfTheLoop) {
  const double fc = 10.0, tau = 0.005;
  std::vector<double> f;
  std::vector<std::complex<double>> l;
  for (double x = 1.0; x <= 100.0; x += 0.125) {
    const double w = kTwoPi * x;
    f.push_back(x);
    l.push_back(kTwoPi * fc / (std::complex<double>(0.0, w)) * std::exp(std::complex<double>(0.0, -w * tau)));
  }
  const auto [gm, pm] = commission::margins_on_grid(f, l);
  ASSERT_TRUE(gm && pm);
  EXPECT_NEAR(*pm, 90.0 - kTwoPi * fc * tau * 180.0 / (kTwoPi / 2.0), 0.2);
  EXPECT_NEAR(*gm, -20.0 * std::log10(kTwoPi * fc / ((kTwoPi / 4.0) / tau)), 0.05);
  // No crossover inside the grid: none reported.
  const std::vector<double> f2(f.begin(), f.begin() + 8);
  const std::vector<std::complex<double>> l2(l.begin(), l.begin() + 8);
  EXPECT_FALSE(commission::margins_on_grid(f2, l2).first);
  EXPECT_FALSE(commission::margins_on_grid(f2, l2).second);
}

}  // namespace
}  // namespace robodamp
