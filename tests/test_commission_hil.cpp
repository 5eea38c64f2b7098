// robodamp commission through the HIL emulator (commission/emulated_cell.hpp): robot A
// (config/commissioning/robot_a_two_modes_hil.yaml, a robot no preset describes) behind the emulator's CAN
// frames and Modbus registers. Commission starts `robodamp plant` as a second process for the measurement,
// the impacts with the tuned controller and each regenerative cut, and runs the controller side through the
// drivers in lockstep; it must end with a verified configuration, the measured improvements within 5
// points of the predicted, and the cuts at the promise less 5 % stable.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "commission/commission.hpp"
#include "commission/emulated_cell.hpp"
#include "config/config.hpp"
#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"
#include "hil_files.hpp"
#include "modal_kit.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;

// Robot A behind the emulator's wires, its own socket and port, a shorter plan (`commissioning` keys).
test::HilFiles robot_a_hil(const std::string& name, const std::string& commissioning) {
  const test::HilFiles f = test::hil_files(name, {{"unix:/tmp/robodamp-hil-commission.sock", "unix:/PLACEHOLDER"}},
                                           "commissioning/robot_a_two_modes_hil");
  std::string text = test::read_file(f.config);
  test::replace_or_throw(text, "unix:/PLACEHOLDER", "unix:" + f.dir + "/can.sock");
  test::replace_or_throw(text, "port: 1512", "port: " + std::to_string(test::free_tcp_port()));
  std::ofstream(f.config) << text << "\ncommissioning: {" << commissioning << "}\n";
  return f;
}

// Commissioning robot A's cell for job A with a short search (the tests are the chain, not the optimum).
commission::CommissionSettings short_commission(const test::HilFiles& f) {
  commission::CommissionSettings s;
  s.config_path = f.config;
  s.job_path = std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/job_a_two_modes.yaml";
  s.out_dir = f.dir + "/out";
  s.command_line = "test";
  s.robodamp_binary = ROBODAMP_BINARY;
  s.tune.global_evaluations = 40;
  s.tune.local_evaluations = 10;
  return s;
}

TEST(CommissionHil, ARobotNoPresetDescribesIsCommissionedAndVerifiedThroughTheEmulator) {
  // Its own socket and port; a shorter plan (3 chirp periods, 4 impacts of 6 s per location).
  const test::HilFiles f =
      robot_a_hil("commission", "chirp_periods: 3, chirp_period_s: 8, impacts_per_location: 4, record_s: 6");
  commission::CommissionSettings s = short_commission(f);
  s.cut_revolutions = 120;
  std::vector<std::string> lines;
  const commission::CommissionResult r = commission::commission(s, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_EQ(r.outcome, commission::Outcome::kVerified)
      << commission::to_string(r.stage) << ": " << r.reason << "\nemulator logs in " << f.dir;

  // The measurement came from the emulator's process (its report says it measured every record).
  const auto m = nlohmann::json::parse(test::read_file(s.out_dir + "/measurement/plant.json"));
  EXPECT_EQ(m["measurement"]["records"], m["measurement"]["records_planned"]);
  EXPECT_EQ(m["measurement"]["records"], 8);
  EXPECT_EQ(m["transport"], "unix:" + f.dir + "/can.sock");
  ASSERT_TRUE(r.identified);
  ASSERT_EQ(r.identified->frfs.front().fit.modes.size(), 2u);
  EXPECT_NEAR(r.identified->frfs.front().fit.modes[0].natural_freq_hz, 5.5, 0.055);
  EXPECT_NEAR(r.identified->frfs.front().fit.modes[1].natural_freq_hz, 16.0, 0.16);

  ASSERT_TRUE(r.cell && r.promise);
  EXPECT_NE(r.cell->cell.find("HIL emulator"), std::string::npos) << r.cell->cell;
  EXPECT_EQ(r.cell->closed_trip, "none");
  EXPECT_DOUBLE_EQ(r.cell->closed_active_share, 1.0);
  ASSERT_EQ(r.cell->frfs.size(), 3u);
  for (const auto& fc : r.cell->frfs) {
    EXPECT_NEAR(fc.measured_improvement_pct, fc.predicted_improvement_pct, 5.0) << fc.name;
    EXPECT_GT(fc.predicted_improvement_pct, 3.0) << fc.name;
  }
  // The regenerative cuts ran in the emulator's process at the promised speeds, at the promise less 5 %.
  ASSERT_EQ(r.cell->cut_trials.size(), 2u);
  const double promised[] = {r.promise->min_depth_mm, r.promise->depth_at_speed_mm};
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& t = r.cell->cut_trials[i];
    EXPECT_TRUE(t.held()) << t.classification << " at " << t.rpm << " rpm";
    EXPECT_NEAR(t.depth_mm, 0.95 * promised[i], 1e-9);
    const auto j =
        nlohmann::json::parse(test::read_file(s.out_dir + "/verify/cut_" + std::to_string(i + 1) + "/plant.json"));
    EXPECT_EQ(j["regenerative_cut"]["classification"], "stable");
    EXPECT_EQ(j["regenerative_cut"]["revolutions"], 120);
    EXPECT_NEAR(j["regenerative_cut"]["axial_mm"].get<double>(), t.depth_mm, 1e-5);
  }
  // Written only because it verified, and it is a configuration for the same wires.
  const config::Config written = config::load_config_file(s.out_dir + "/configuration.yaml");
  EXPECT_EQ(written.controller.gain_ns_per_m, r.tuned_config->controller.gain_ns_per_m);
  ASSERT_TRUE(written.can);
  EXPECT_EQ(written.can->interface, "unix:" + f.dir + "/can.sock");
  EXPECT_NE(test::read_file(s.out_dir + "/configuration.yaml").find("HIL emulator"), std::string::npos);
  EXPECT_NE(test::read_file(s.out_dir + "/report.html").find("the regenerative cut in the HIL emulator"),
            std::string::npos);
}

TEST(CommissionHil, ARealCanBusIsRefusedWithTheReason) {
  const test::HilFiles f = test::hil_files("commission_can", {{"unix:/tmp/robodamp-hil-commission.sock", "can0"}},
                                           "commissioning/robot_a_two_modes_hil");
  commission::CommissionSettings s;
  s.config_path = f.config;
  s.job_path = std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/job_a_two_modes.yaml";
  s.out_dir = f.dir + "/out";
  const commission::CommissionResult r = commission::commission(s, [](const std::string&) {});
  EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
  EXPECT_EQ(r.stage, commission::Stage::kMeasure);
  EXPECT_NE(r.reason.find("can.interface = can0"), std::string::npos) << r.reason;
  EXPECT_FALSE(fs::exists(s.out_dir + "/configuration.yaml"));
}

// An emulator that goes silent mid-run (SIGSTOP once the controller is connected, by a wrapper around the
// real `robodamp plant`) ends the cut across processes with a clear error within the stall watch's 30 s of
// wall time, naming the emulator's log, instead of holding the caller for a 1 s lockstep wait per tick.
TEST(CommissionHil, AnEmulatorThatGoesSilentEndsTheCutWithTheReason) {
  const test::HilFiles f = test::hil_files("silent_emulator");
  const std::string pidfile = f.dir + "/plant.pid", wrapper = f.dir + "/frozen_plant.sh";
  std::ofstream(wrapper) << "#!/bin/bash\n"
                            "\"" ROBODAMP_BINARY
                            "\" \"$@\" > >(while IFS= read -r l; do echo \"$l\"; "
                            "[[ $l == *'controller connected'* ]] && kill -STOP \"$(cat " +
                                pidfile +
                                ")\"; done) 2>&1 &\n"
                                "echo $! > " +
                                pidfile + "\nwait $!\n";
  fs::permissions(wrapper, fs::perms::owner_all);
  const config::Config cell = config::load_config_file(f.config);
  const std::string job = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml";
  std::string what;
  try {
    // 5 s without a fresh sample ends it (the product's 30 s, shortened: the test checks the way out, not the wait).
    (void)commission::cut_through_emulator(cell, cell, {wrapper, f.config, job, 60, 5.0}, 700.0, 0.5, f.dir + "/cut");
  } catch (const std::runtime_error& e) {
    what = e.what();
  }
  // The frozen plant, whoever its parent was, goes now.
  std::ifstream pid_in(pidfile);
  pid_t pid = 0;
  if (pid_in >> pid && pid > 0) ::kill(pid, SIGKILL);
  EXPECT_NE(what.find("the lockstep stalled: no fresh sensor sample for 5 s"), std::string::npos) << what;
  EXPECT_NE(what.find(f.dir + "/cut/plant.log"), std::string::npos) << what;
  EXPECT_NE(what.find("controller connected"), std::string::npos) << what;  // the log's tail
}

// The integrator's modal kit: an impact test of robot A on the simulated plant (another noise seed),
// exported with every FRF 2 % off (the kit's calibration), without the actuator (tests/modal_kit.hpp).
std::string modal_kit_export(const std::string& dir) {
  std::string robot =
      test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/robot_a_two_modes.yaml");
  test::replace_or_throw(robot, "  seed: 1", "  seed: 29");
  std::ofstream(dir + "/kit_robot.yaml") << robot;
  return test::modal_kit_export(dir + "/kit_robot.yaml", dir + "/kit", dir + "/tap_tests.uff", 1.02);
}

// A real cell (the emulator told so: no impacts served, no cut): the actuator is the shaker, the tool tip's
// FRFs come from the user's tap tests. Identified within 1 %, verified by the chirp with control off and on:
// the improvement at the actuator within 5 points of the prediction, the loop gain measured by injection
// within 1 dB and 5 deg of the analysis.
TEST(CommissionHil, ARealCellIsCommissionedWithTheActuatorAsTheShakerAndTheUsersTapTests) {
  const test::HilFiles f = robot_a_hil("commission_real", "chirp_periods: 3, chirp_period_s: 8");
  commission::CommissionSettings s = short_commission(f);
  s.tap_tests = {modal_kit_export(f.dir)};
  std::vector<std::string> lines;
  const commission::CommissionResult r = commission::commission(s, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_EQ(r.outcome, commission::Outcome::kVerified)
      << commission::to_string(r.stage) << ": " << r.reason << "\nemulator logs in " << f.dir;
  EXPECT_TRUE(r.real_cell);

  // No hammer and no cut in the emulator, in either run on the cell.
  for (const char* run : {"/measurement/plant.json", "/verify/chirp_on/plant.json"}) {
    const auto j = nlohmann::json::parse(test::read_file(s.out_dir + run));
    EXPECT_EQ(j["impacts"]["records"], 0) << run;
    EXPECT_FALSE(j["impacts"]["started"].get<bool>()) << run;
    EXPECT_TRUE(j["regenerative_cut"].is_null()) << run;
  }
  // Identified from the tap tests, within 1 % of the robot's modes; the tap tests agree with the chirp.
  ASSERT_TRUE(r.identified && r.tap_check);
  for (const auto& fr : r.identified->frfs) {
    ASSERT_EQ(fr.fit.modes.size(), 2u) << fr.name;
    EXPECT_NEAR(fr.fit.modes[0].natural_freq_hz, 5.5, 0.055) << fr.name;
    EXPECT_NEAR(fr.fit.modes[1].natural_freq_hz, 16.0, 0.16) << fr.name;
    EXPECT_NE(fr.file.find("tap_tests.uff record"), std::string::npos) << fr.file;
  }
  EXPECT_EQ(r.tap_check->failure(), "");
  ASSERT_EQ(r.tap_check->modes.size(), 2u);

  // Verified on the cell by the chirp: the improvement at the actuator and the loop gain.
  ASSERT_TRUE(r.real_check);
  const commission::RealCellCheck& c = *r.real_check;
  EXPECT_NE(c.cell.find("the HIL emulator as a real cell"), std::string::npos) << c.cell;
  EXPECT_EQ(c.closed_trip, "none");
  EXPECT_DOUBLE_EQ(c.closed_active_share, 1.0);
  ASSERT_EQ(c.modes.size(), 2u);
  bool damps = false;
  for (const auto& m : c.modes) {
    EXPECT_NEAR(m.measured_improvement_pct, m.predicted_improvement_pct, 5.0) << m.freq_hz;
    damps = damps || m.predicted_improvement_pct > 5.0;
  }
  EXPECT_TRUE(damps) << "the tuned loop damps neither mode at the actuator";
  const commission::LoopGainCheck& g = c.loop_gain;
  EXPECT_GT(g.compared_points, 10);
  EXPECT_LE(g.max_error_db, 1.0);
  EXPECT_LE(g.max_error_deg, 5.0);
  ASSERT_TRUE(g.measured_gm_db && g.predicted_gm_db);
  EXPECT_NEAR(*g.measured_gm_db, *g.predicted_gm_db, 1.0);
  EXPECT_FALSE(r.cell);  // no impact check, no cut in the emulator

  const std::string written = test::read_file(s.out_dir + "/configuration.yaml");
  EXPECT_NE(written.find("No hammer and no cut on the machine"), std::string::npos);
  EXPECT_NE(test::read_file(s.out_dir + "/report.html").find("Verification on a real cell"), std::string::npos);
}

// An amplifier that is not ready when the chirp is due (the emulator's takes 10 s, the loop gives it 2): the
// commissioning is refused at the measurement, before the actuator moved, and nothing is written.
TEST(CommissionHil, ARealCellThatIsNotReadyIsRefusedBeforeTheActuatorMoves) {
  const test::HilFiles f = robot_a_hil("commission_not_ready", "chirp_periods: 3, chirp_period_s: 8");
  std::string text = test::read_file(f.config);
  test::replace_or_throw(text, "amplifier_ready_delay_s: 0.005", "amplifier_ready_delay_s: 10");
  std::ofstream(f.config) << text;
  commission::CommissionSettings s = short_commission(f);
  std::ofstream(f.dir + "/taps.uff") << "";  // never read: the measurement stops first
  s.tap_tests = {f.dir + "/taps.uff"};
  const commission::CommissionResult r = commission::commission(s, [](const std::string&) {});
  EXPECT_EQ(r.outcome, commission::Outcome::kRefused) << r.reason;
  EXPECT_EQ(r.stage, commission::Stage::kMeasure);
  EXPECT_NE(r.reason.find("not ready: the loop is"), std::string::npos) << r.reason;
  EXPECT_EQ(commission::exit_code(r.outcome), 6);
  EXPECT_FALSE(fs::exists(s.out_dir + "/configuration.yaml"));
}

}  // namespace
}  // namespace robodamp
