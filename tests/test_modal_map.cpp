// The modes between measured poses (robot/modal_map.*, analysis::pose_modes with measured_modes;
// docs/pose_dynamics.md, "Modes between measured poses"): the regression itself, a robot whose model is wrong
// in form (a joint's translational compliance the model lacks) mapped from a few poses and checked at poses
// held out, and the file's section read, written and refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

#include "analysis/pose_schedule.hpp"
#include "config/milling_config.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/structure.hpp"
#include "config/config.hpp"
#include "config/pose_schedule_config.hpp"
#include "config/robot_model_config.hpp"
#include "robot/modal_map.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

// The regression passes through its data (to the noise), its uncertainty is smallest there and grows away
// from it towards the model's whole scatter, and far away it tends to the mean ratio.
TEST(ModalMap, TheRegressionPassesThroughItsDataAndItsSpreadGrowsAwayFromIt) {
  std::vector<Eigen::VectorXd> x;
  std::vector<double> y;
  for (const double q : {0.0, 0.4, 0.8, 1.2}) {
    x.push_back(Eigen::VectorXd::Constant(1, q));
    y.push_back(0.05 * std::sin(2.0 * q) + 0.02);
  }
  const robot::ModalMap::Field f(x, y, 0.003);
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_NEAR(f.mean(x[i]), y[i], 0.004) << i;
    EXPECT_LT(f.sigma(x[i]), 0.004) << i;
  }
  // Outside the data the spread grows with the distance.
  const auto at = [](double q) { return Eigen::VectorXd::Constant(1, q); };
  EXPECT_GT(f.sigma(at(1.6)), f.sigma(at(1.3)));
  EXPECT_GT(f.sigma(at(3.0)), f.sigma(at(1.6)));
  double mean_sq = 0.0;
  for (double v : y) mean_sq += v * v / 4.0;
  // Far away: a constant within the data's range (the length scales' mean ratios, weighted; none longer than
  // the data's span, whose mean is ill-posed), the spread at least the model's whole error.
  EXPECT_NEAR(f.mean(at(20.0)), f.mean(at(40.0)), 1e-9);
  EXPECT_GT(f.mean(at(20.0)), *std::min_element(y.begin(), y.end()));
  EXPECT_LT(f.mean(at(20.0)), *std::max_element(y.begin(), y.end()));
  EXPECT_GE(f.sigma(at(20.0)), std::sqrt(mean_sq) * 0.99);
  // One point: the ratio there everywhere, no better than that point's size away from it.
  const robot::ModalMap::Field one({at(0.5)}, {0.04}, 0.003);
  EXPECT_NEAR(one.mean(at(0.5)), 0.04, 1e-9);
  EXPECT_NEAR(one.mean(at(2.0)), 0.04, 1e-9);
  EXPECT_GE(one.sigma(at(2.0)), 0.0399);
}

// Two poses say nothing about the length scale (their likelihood is the same at every one): the regression
// averages over them, so a measurement that moves by far less than its noise moves the prediction between the
// poses by as little. Choosing the most likely scale picked one by rounding (the path commissioning's held-out
// stop mapped 0.6 %, 1.3 % or 2.3 % from its measured mode in runs that differed by the noise alone).
TEST(ModalMap, TheRegressionMovesLittleWhenItsDataMoveLittle) {
  const auto at = [](double a, double b) {
    Eigen::VectorXd v(2);
    v << a, b;
    return v;
  };
  const std::vector<Eigen::VectorXd> x = {at(0.17, 1.57), at(2.44, 1.57)};
  const Eigen::VectorXd between = at(0.87, 1.57);
  const robot::ModalMap::Field f(x, {0.0077, 0.0415}, 0.003);
  for (int k = 1; k <= 20; ++k) {
    const double d = 1e-7 * (k % 2 == 0 ? k : -k);
    const robot::ModalMap::Field g(x, {0.0077 + d, 0.0415 - d}, 0.003);
    EXPECT_NEAR(g.mean(between), f.mean(between), 1e-5) << k;
    EXPECT_NEAR(g.sigma(between), f.sigma(between), 1e-5) << k;
  }
  // Between the two: inside their range, with a spread that covers the gap to either.
  EXPECT_GT(f.mean(between), 0.0077);
  EXPECT_LT(f.mean(between), 0.0415);
  EXPECT_GT(f.sigma(between), 0.5 * std::min(f.mean(between) - 0.0077, 0.0415 - f.mean(between)));
}

const std::string kSource = ROBODAMP_SOURCE_DIR;

// The compact arm of config/robots/compact_three_link.yaml as its file says (the model), and the robot it
// stands for (the truth): the elbow's bearings give 1.7 um per N in translation, a compliance the model's
// torsional-only joints do not have, so no choice of its joint stiffnesses reproduces the truth's modes at
// every pose.
struct WrongInForm {
  config::RobotModelConfig model = config::load_robot_model(kSource + "/config/robots/compact_three_link.yaml");
  config::RobotModelConfig truth = [this] {
    config::RobotModelConfig t = model;
    t.joints[1].translational_stiffness_n_per_m = 6e5;
    return t;
  }();
  static constexpr int kAxis = 0, kModes = 3;
};

// What a modal test measures at a pose: the truth's modes along the axis, each frequency and stiffness off by
// a fixed +-0.2 % and +-2 % (the identification's scatter), damping by +-5 %.
config::MeasuredPoseModes measured_at(const WrongInForm& w, const std::string& name, const std::vector<double>& q) {
  config::MeasuredPoseModes p{name, q, {}};
  int sign = 1;
  for (const robot::AxisMode& m : robot::axis_modes(w.truth, q, w.kAxis, w.kModes)) {
    p.modes.push_back(config::stiffness_mode(m.freq_hz * (1.0 + 0.002 * sign), m.damping_ratio * (1.0 - 0.05 * sign),
                                             m.stiffness_n_per_m * (1.0 + 0.02 * sign)));
    sign = -sign;
  }
  return p;
}

// The nearest mode's frequency error, %.
double freq_error_pct(const analysis::PoseModes& got, double truth_hz) {
  double best = INFINITY;
  for (const auto& m : got.modes)
    if (std::abs(m.natural_freq_hz / truth_hz - 1.0) < std::abs(best)) best = m.natural_freq_hz / truth_hz - 1.0;
  return 100.0 * best;
}

// Issue 51 item 2, in process, with the model file as the prior (not fitted): measured at five poses of the
// HIL path (joint 2 30, 65, 80, 100, 130 deg), the map puts every mode of the truth at three poses between them
// within 2 % (the model file is up to 28 % off and lacks a mode), the damped improvement a set designed on the
// map predicts there within 5 points of what a measurement at that pose would predict (its modes off as the
// measured ones are), and outside the measured poses its spread is larger than
// at any of them.
TEST(ModalMap, ARobotWrongInFormIsMappedFromFivePosesAndThePosesBetweenComeWithinTwoPercent) {
  const WrongInForm w;
  config::RobotModelConfig mapped = w.model;
  mapped.measured_modes = config::MeasuredModesConfig{w.kAxis, {}};
  const std::vector<std::pair<std::string, std::vector<double>>> in_map{
      {"a", {-90, 30, 30}}, {"c", {-90, 65, 30.5}}, {"g", {-90, 80, 30}}, {"h", {-90, 100, 30}}, {"f", {-90, 130, 30}}};
  const std::vector<std::pair<std::string, std::vector<double>>> held{
      {"b", {-90, 50, 29.5}}, {"d", {-90, 90, 30}}, {"e", {-90.25, 110, 29.5}}};
  for (const auto& [name, q] : in_map) mapped.measured_modes->poses.push_back(measured_at(w, name, q));
  // The set: the configuration's controller designed for one region over the path (the analysis's polarity
  // and match frequency at its centre), on the map's modes.
  config::Config cfg = config::load_config_file(kSource + "/config/hil_pose_schedule.yaml");
  cfg.pose_schedule->regions = {config::PoseRegionConfig{"path", {-91, 30, 29}, {-89, 130, 31}, 100.0, {}, {}, {}}};
  cfg.pose_schedule->workspace_min_deg = {-91, 30, 29};
  cfg.pose_schedule->workspace_max_deg = {-89, 130, 31};
  const analysis::RegionSet set = analysis::design_region(cfg, mapped, 0);
  double worst_mapped = 0.0, worst_model = 0.0, worst_points = 0.0;
  // Each measured mode's frequency spread (lowest first): the largest at a measured pose.
  std::vector<double> largest_map_sigma(3, 0.0);
  const auto spreads = [](const analysis::PoseModes& pm) {
    std::vector<double> out;
    for (const auto& c : pm.corrections)
      if (c.measured_poses > 0) out.push_back(c.freq_sigma);
    return out;
  };
  for (const auto& [name, q] : held) {
    const analysis::PoseModes got = analysis::pose_modes(mapped, q, w.kAxis, w.kModes);
    const analysis::PoseModes model = analysis::pose_modes(w.model, q, w.kAxis, w.kModes);
    for (const robot::AxisMode& t : robot::axis_modes(w.truth, q, w.kAxis, w.kModes)) {
      const double e_map = freq_error_pct(got, t.freq_hz), e_model = freq_error_pct(model, t.freq_hz);
      std::cout << name << " " << t.freq_hz << " Hz: model " << e_model << " %, map " << e_map << " %\n";
      worst_mapped = std::max(worst_mapped, std::abs(e_map));
      worst_model = std::max(worst_model, std::abs(e_model));
    }

    const double p_map = analysis::predicted_improvement_pct(set.config, mapped, *cfg.pose_schedule, q);
    const double p_truth = analysis::predicted_improvement_pct(set.config, w.truth, *cfg.pose_schedule, q);
    const double p_model = analysis::predicted_improvement_pct(set.config, w.model, *cfg.pose_schedule, q);
    // What a measurement at the held-out pose itself would predict (its modes off as the others are): the
    // measurements' own error, which no interpolation between poses removes.
    config::RobotModelConfig there = w.model;
    there.measured_modes = config::MeasuredModesConfig{w.kAxis, {measured_at(w, name, q)}};
    const double p_there = analysis::predicted_improvement_pct(set.config, there, *cfg.pose_schedule, q);
    std::cout << name << ": damped improvement predicted on the map " << p_map << " %, measured there " << p_there
              << " %, the truth " << p_truth << " %, the model file " << p_model << " %\n";
    worst_points = std::max(worst_points, std::abs(p_map - p_there));
    // The map states its uncertainty there: the truth within two of its sigmas; the model file states none.
    const analysis::PredictedImprovement band =
        analysis::predicted_improvement(set.config, mapped, *cfg.pose_schedule, q);
    std::cout << name << ": the map's one sigma " << band.sigma_pct << " points\n";
    EXPECT_DOUBLE_EQ(band.pct, p_map);
    EXPECT_GT(band.sigma_pct, 0.0) << name;
    EXPECT_LE(std::abs(p_map - p_truth), 2.0 * band.sigma_pct) << name;
    EXPECT_EQ(analysis::predicted_improvement(set.config, w.model, *cfg.pose_schedule, q).sigma_pct, 0.0);
    // Against the truth the map is no more than 5 points worse than a measurement at the pose itself.
    EXPECT_LT(std::abs(p_map - p_truth), std::abs(p_there - p_truth) + 5.0) << name;
  }
  for (const auto& [name, q] : in_map) {
    const analysis::PoseModes got = analysis::pose_modes(mapped, q, w.kAxis, w.kModes);
    const config::MeasuredPoseModes m = measured_at(w, name, q);
    for (const auto& mm : m.modes) EXPECT_LT(std::abs(freq_error_pct(got, mm.natural_freq_hz)), 0.5) << name;
    const std::vector<double> sg = spreads(got);
    ASSERT_EQ(sg.size(), 3U);
    for (std::size_t i = 0; i < 3; ++i) largest_map_sigma[i] = std::max(largest_map_sigma[i], sg[i]);
  }
  std::cout << "held out: the map's largest frequency error " << worst_mapped << " %, the model file's " << worst_model
            << " %; the damped improvement within " << worst_points << " points of a measurement at the pose\n";
  EXPECT_LT(worst_mapped, 2.0);
  EXPECT_GT(worst_model, 2.0);   // the case is one the model file alone does not meet
  EXPECT_LT(worst_points, 5.0);  // measured: 0.6, 0.07 and 4.5 points (docs/pose_dynamics.md)
  // Outside the measured poses (joint 2 at the ends of its travel, 20 and 30 deg beyond them) the spread is
  // larger than anywhere measured.
  for (const double q2 : {10.0, 160.0}) {
    const std::vector<double> sg = spreads(analysis::pose_modes(mapped, {-90, q2, 30}, w.kAxis, w.kModes));
    ASSERT_EQ(sg.size(), 3U);
    for (std::size_t i = 0; i < 3; ++i) {
      std::cout << "mode " << i + 1 << ": frequency sigma at the measured poses <= " << 100 * largest_map_sigma[i]
                << " %, at joint 2 = " << q2 << " deg " << 100 * sg[i] << " %\n";
      EXPECT_GT(sg[i], largest_map_sigma[i]) << i;
    }
  }
}

// The form each quantity is interpolated in is the data's choice (leave-one-out), not the code's: a robot the
// model describes in form (every joint 20 % stiffer, its damping as the model's) keeps the model as the prior of
// every quantity of its three modes, and puts every mode at three poses between the measured ones within 0.5 %;
// the robot wrong in form (above) has the damping of both its matched modes interpolated on its own, where the
// model's varies with the pose and the measured does not.
// A mode the measurement at a pose did not see, where it would have (below the highest mode measured there),
// is there but does not move the TCP along the axis. The path commissioning's robot (the planar robot with a
// stiffer elbow, a softer wrist and a heavier second link, tests/test_path_commission.cpp) measured along x at
// joint 2 = 10, 100 and 140 deg: at 10 deg its 21 Hz mode moves along y only (7e9 N/m along x) and the modal test
// there finds 9 and 52 Hz. The map carried the 21 Hz mode's participation along x from 100 and 140 deg into
// 10 deg (5.9e5 N/m there, twice the dominant mode's participation; 2.3e6 in another run), and the wall cut's limit
// at 700 rpm on the map was 0.161 or 0.340 mm where the robot's is 0.098 mm. Now each measured pose's
// participations are the measured ones, and the cut's limit on the map within 15 % of the robot's at every stop
// and at the one held out (50 deg).
TEST(ModalMap, AModeAMeasuredPoseDidNotSeeDoesNotMoveTheTcpAlongTheAxisThere) {
  const config::RobotModelConfig model = config::load_robot_model(kSource + "/config/robots/planar_three_link.yaml");
  config::RobotModelConfig truth = model;
  truth.joints[1].stiffness_nm_per_rad = 4.6e5;
  truth.joints[2].stiffness_nm_per_rad = 3.6e3;
  truth.links[1].mass_kg = 128.0;
  constexpr int kAxis = 0, kModes = 3;
  const auto participation = [](double f_hz, double k) { return std::pow(2.0 * M_PI * f_hz, 2) / k; };
  // What the modal test finds: the truth's modes along x but those below 0.1 % of the pose's largest participation.
  const auto measured = [&](const std::string& name, const std::vector<double>& q) {
    config::MeasuredPoseModes p{name, q, {}};
    const std::vector<robot::AxisMode> all = robot::axis_modes(truth, q, kAxis, kModes);
    double largest = 0.0;
    for (const auto& m : all) largest = std::max(largest, participation(m.freq_hz, m.stiffness_n_per_m));
    for (const auto& m : all)
      if (participation(m.freq_hz, m.stiffness_n_per_m) >= 1e-3 * largest)
        p.modes.push_back(config::stiffness_mode(m.freq_hz, m.damping_ratio, m.stiffness_n_per_m));
    return p;
  };
  config::RobotModelConfig mapped = model;
  mapped.measured_modes = config::MeasuredModesConfig{kAxis, {}};
  for (const double q2 : {10.0, 100.0, 140.0})
    mapped.measured_modes->poses.push_back(measured("q" + std::to_string(static_cast<int>(q2)), {-100, q2, 90}));
  ASSERT_EQ(mapped.measured_modes->poses[0].modes.size(), 2U);  // the 21 Hz mode not seen at 10 deg
  // At each measured pose every mapped mode's participation along x is the measured one (within 5 %) or, where
  // nothing was measured, below 2 % of the pose's largest (the regression's noise is 1 % of the track's largest).
  for (const auto& p : mapped.measured_modes->poses) {
    const analysis::PoseModes got = analysis::pose_modes(mapped, p.joints_deg, kAxis, kModes);
    double largest = 0.0;
    for (const auto& m : p.modes) largest = std::max(largest, participation(m.natural_freq_hz, m.stiffness_n_per_m));
    for (const auto& g : got.modes) {
      const double pg = participation(g.natural_freq_hz, g.stiffness_n_per_m);
      const auto near = std::find_if(p.modes.begin(), p.modes.end(), [&](const config::ModeConfig& m) {
        return std::abs(m.natural_freq_hz / g.natural_freq_hz - 1.0) < 0.02;
      });
      if (near != p.modes.end())
        EXPECT_NEAR(pg / participation(near->natural_freq_hz, near->stiffness_n_per_m), 1.0, 0.05)
            << p.name << " " << g.natural_freq_hz << " Hz";
      else
        EXPECT_LT(pg, 0.02 * largest) << p.name << " " << g.natural_freq_hz << " Hz: " << g.stiffness_n_per_m << " N/m";
    }
  }
  // A set's improvement predicted at a stop is as sure as the measurement there, the unseen mode too: its
  // participation moves by its sigma, not by a factor (the stiffness's log moved by its 874 % sigma made a
  // mode 6,600 times softer, and the prediction -32 +/- 571 %).
  {
    config::Config cfg = config::load_config_file(kSource + "/config/hil_pose_schedule.yaml");
    cfg.pose_schedule->regions = {config::PoseRegionConfig{"path", {-102, 0, 88}, {-98, 140, 92}, 100.0, {}, {}, {}}};
    cfg.pose_schedule->workspace_min_deg = {-102, 0, 88};
    cfg.pose_schedule->workspace_max_deg = {-98, 140, 92};
    const analysis::RegionSet set = analysis::design_region(cfg, mapped, 0);
    for (const auto& p : mapped.measured_modes->poses) {
      const auto b = analysis::predicted_improvement(set.config, mapped, *cfg.pose_schedule, p.joints_deg);
      std::cout << p.name << ": the set's improvement " << b.pct << " +/- " << b.sigma_pct << " %\n";
      EXPECT_LT(b.sigma_pct, 0.05 * (100.0 + b.pct)) << p.name;
    }
  }
  // The wall cut at 700 rpm, the robot in its plane: on the map within 15 % of the robot's, at the stops and the
  // pose held out.
  const test::ScratchDir dir("unseen_mode");
  std::ofstream(dir.file("mapped.yaml")) << config::robot_model_yaml(mapped);
  std::ofstream(dir.file("truth.yaml")) << config::robot_model_yaml(truth);
  config::MillingConfig job = config::load_milling_config(kSource + "/config/milling/planar_three_link_wall_x.yaml");
  const auto limit_mm = [&](const std::string& file, double q2) {
    config::StructureConfig st = job.structures.front();
    st.parts.front().pose->model_path = dir.file(file);
    st.parts.front().pose->joints_deg = {-100, q2, 90};
    return milling::AccurateStability(milling::Structure(st, false), job).critical(700.0, 0.1).critical_depth_mm;
  };
  for (const double q2 : {10.0, 50.0, 100.0, 140.0}) {
    const double on_map = limit_mm("mapped.yaml", q2), robot = limit_mm("truth.yaml", q2);
    std::cout << "joint 2 = " << q2 << " deg: the wall at 700 rpm " << on_map << " mm on the map, " << robot
              << " mm the robot's\n";
    EXPECT_NEAR(on_map / robot, 1.0, 0.15) << q2;
  }
}

TEST(ModalMap, TheModelStaysThePriorWhereItIsRightInFormAndIsLeftOutWhereItIsWrong) {
  const WrongInForm w;
  config::RobotModelConfig stiffer = w.model;
  for (auto& j : stiffer.joints) j.stiffness_nm_per_rad *= 1.2;
  const std::vector<std::pair<std::string, std::vector<double>>> in_map{
      {"a", {-90, 30, 30}}, {"c", {-90, 65, 30.5}}, {"g", {-90, 80, 30}}, {"h", {-90, 100, 30}}, {"f", {-90, 130, 30}}};
  const auto forms_of = [&](const config::RobotModelConfig& truth) {
    config::RobotModelConfig mapped = w.model;
    mapped.measured_modes = config::MeasuredModesConfig{w.kAxis, {}};
    for (const auto& [name, q] : in_map) {
      config::MeasuredPoseModes p{name, q, {}};
      for (const robot::AxisMode& m : robot::axis_modes(truth, q, w.kAxis, w.kModes))
        p.modes.push_back(config::stiffness_mode(m.freq_hz, m.damping_ratio, m.stiffness_n_per_m));
      mapped.measured_modes->poses.push_back(p);
    }
    return std::pair{mapped, robot::ModalMap(mapped, w.kAxis, w.kModes).forms()};
  };
  const auto [right, right_forms] = forms_of(stiffer);
  int matched = 0;
  for (const robot::TrackForm& f : right_forms) {
    if (f.model_index < 0) continue;
    ++matched;
    EXPECT_FALSE(f.freq.own) << f.model_index << ": " << f.freq.own_rms << " own, " << f.freq.model_rms
                             << " against the model";
    EXPECT_FALSE(f.damping.own) << f.model_index;
    EXPECT_FALSE(f.stiffness.own) << f.model_index;
  }
  EXPECT_EQ(matched, 3);
  // Between the measured poses the prior carries the shape.
  for (const auto& q : {std::vector<double>{-90, 50, 29.5}, {-90, 90, 30}, {-90.25, 110, 29.5}}) {
    const std::vector<robot::AxisMode> truth = robot::axis_modes(stiffer, q, w.kAxis, w.kModes);
    const analysis::PoseModes got = analysis::pose_modes(right, q, w.kAxis, w.kModes);
    ASSERT_EQ(got.modes.size(), truth.size());
    for (std::size_t i = 0; i < truth.size(); ++i)
      EXPECT_NEAR(got.modes[i].natural_freq_hz / truth[i].freq_hz, 1.0, 0.005) << i;
  }
  int damping_own = 0;
  for (const robot::TrackForm& f : forms_of(w.truth).second)
    if (f.model_index >= 0) damping_own += f.damping.own ? 1 : 0;
  EXPECT_EQ(damping_own, 2);
}

// The section read back as written, in a block style a person writes, and refused where it is wrong, by key.
TEST(ModalMap, TheMeasuredModesSectionIsReadWrittenAndRefusedByKey) {
  const WrongInForm w;
  config::RobotModelConfig m = w.model;
  m.measured_modes =
      config::MeasuredModesConfig{0, {measured_at(w, "a", {-90, 30, 30}), measured_at(w, "f", {-90, 130, 30})}};
  const config::RobotModelConfig back = config::parse_robot_model(config::robot_model_yaml(m), "written");
  ASSERT_TRUE(back.measured_modes);
  EXPECT_EQ(back.measured_modes->axis, 0);
  ASSERT_EQ(back.measured_modes->poses.size(), 2U);
  EXPECT_EQ(back.measured_modes->poses[1].name, "f");
  // Written to 10 significant digits.
  EXPECT_NEAR(
      back.measured_modes->poses[1].modes[0].natural_freq_hz / m.measured_modes->poses[1].modes[0].natural_freq_hz, 1.0,
      1e-9);
  EXPECT_NEAR(
      back.measured_modes->poses[1].modes[2].stiffness_n_per_m / m.measured_modes->poses[1].modes[2].stiffness_n_per_m,
      1.0, 1e-9);
  const std::string base = test::read_file(kSource + "/config/robots/compact_three_link.yaml");
  const auto refused = [&](const std::string& section, const std::string& what) {
    try {
      (void)config::parse_robot_model(base + section, "mine.yaml");
      ADD_FAILURE() << "accepted: " << section;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(
      "measured_modes:\n  axis: z\n  poses:\n    - name: a\n      joints_deg: [-90, 30, 30]\n      modes:\n"
      "        - natural_freq_hz: 12\n          damping_ratio: 0.02\n          stiffness_n_per_m: 1e6\n",
      "measured_modes.axis");
  refused(
      "measured_modes:\n  poses:\n    - {name: a, joints_deg: [-90, 200, 30], modes: [{natural_freq_hz: 12, "
      "damping_ratio: 0.02, "
      "stiffness_n_per_m: 1e6}]}\n",
      "measured_modes.poses[0].joints_deg");
  refused(
      "measured_modes:\n  poses:\n    - {name: a, joints_deg: [-90, 30, 30], modes: [{natural_freq_hz: 12, "
      "damping_ratio: 0, "
      "stiffness_n_per_m: 1e6}]}\n",
      "measured_modes.poses[0].modes[0].damping_ratio");
  refused("measured_modes:\n  poses:\n    - {name: a, joints_deg: [-90, 30, 30]}\n", "measured_modes.poses[0].modes");
  // Measured along y, asked along x: refused with both.
  config::RobotModelConfig y = m;
  y.measured_modes->axis = 1;
  try {
    (void)analysis::pose_modes(y, {-90, 50, 30}, 0, 3);
    ADD_FAILURE() << "another axis accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("measured_modes are along y"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace robodamp
