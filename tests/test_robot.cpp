// Pose-dependent robot dynamics (robot/): the beam element against Euler-Bernoulli's cantilever, the
// receptance coupling against the assembled model, the planar-robot study's preset at its three poses.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <random>

#include "config/robot_model_config.hpp"
#include "robot/planar_chain.hpp"
#include "robot/pose_fit.hpp"
#include "robot/robot_model.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A steel-like cantilever: the first three bending frequencies within 0.5 % of (beta_n L)^2 / (2 pi L^2)
// sqrt(EI / (rho A)), beta_n L = 1.87510, 4.69409, 7.85476. The clamp is the base joint made very stiff.
TEST(RobotModel, CantileverMatchesEulerBernoulli) {
  robot::ChainModel m;
  const double length = 1.2, mass = 30.0, ei = 2.0e6;
  m.links = {{length, mass, ei, 1e12, 12}};
  m.joints = {{1e13, 0.0}};
  const robot::PlanarChain c(m, {0.3});
  const auto modes = c.modes(3);
  const double beta_l[3] = {1.87510407, 4.69409113, 7.85475744};
  for (int i = 0; i < 3; ++i) {
    const double exact = beta_l[i] * beta_l[i] / (2.0 * M_PI * length * length) * std::sqrt(ei / (mass / length));
    std::cout << "mode " << i + 1 << ": " << modes[static_cast<std::size_t>(i)].freq_hz << " Hz, Euler-Bernoulli "
              << exact << " Hz\n";
    EXPECT_NEAR(modes[static_cast<std::size_t>(i)].freq_hz / exact, 1.0, 0.005) << i;
  }
}

robot::ChainModel three_links() {
  robot::ChainModel m;
  m.links = {{0.9, 41.0, 9.6e6, 5e9, 6}, {1.04, 121.0, 9.6e6, 5e9, 6}, {0.2, 15.8, 9.6e6, 5e9, 2}};
  m.joints = {{2.25e6, 0.02}, {4.05e5, 0.02}, {3.99e3, 0.01}};
  m.head_mass_kg = 5.0;
  m.head_inertia_kgm2 = 0.05;
  return m;
}

// Receptance coupling of the free-free links equals the assembled model at every frequency (1e-6 relative).
TEST(RobotModel, ReceptanceCouplingEqualsTheAssembledModel) {
  const robot::PlanarChain c(three_links(), {-120.13 * kDeg, 133.37 * kDeg, -14.13 * kDeg});
  double worst = 0.0;
  for (double f = 0.5; f < 400.0; f *= 1.07) {
    const Eigen::Matrix2cd d = c.tcp_frf_direct(f), r = c.tcp_frf_rcsa(f);
    worst = std::max(worst, (d - r).norm() / d.norm());
  }
  for (const auto& md : c.modes(4)) {  // at the resonances too
    const Eigen::Matrix2cd d = c.tcp_frf_direct(md.freq_hz), r = c.tcp_frf_rcsa(md.freq_hz);
    worst = std::max(worst, (d - r).norm() / d.norm());
  }
  std::cout << "largest relative difference: " << worst << "\n";
  EXPECT_LT(worst, 1e-6);
  // Reciprocity: the assembled TCP receptance is symmetric, to the round-off of one complex solve of a stiffness
  // whose links (EA 5e9 N) and wrist joint (4e3 N m/rad) are far apart: 1.1e-9 relative in the x86-64-v3 build,
  // under 1e-9 in the x86-64 one. A term left out of the assembly would be of order one.
  const Eigen::Matrix2cd g = c.tcp_frf_direct(12.0);
  EXPECT_LT(std::abs(g(0, 1) - g(1, 0)) / std::abs(g(0, 0)), 1e-8);
}

// A joint whose bearings give in translation (a compliance the torsional-only model lacks): the two
// ways still agree, the modes soften, and a very stiff bearing is the rigid joint again.
TEST(RobotModel, AJointsTranslationalComplianceIsCoupledAlikeBothWays) {
  robot::ChainModel soft = three_links();
  soft.joints[0].translational_stiffness_n_per_m = 4e6;  // to the base
  soft.joints[1].translational_stiffness_n_per_m = 2e6;  // the elbow
  const std::vector<double> q{-120.13 * kDeg, 133.37 * kDeg, -14.13 * kDeg};
  const robot::PlanarChain c(soft, q);
  double worst = 0.0;
  for (double f = 0.5; f < 400.0; f *= 1.07) {
    const Eigen::Matrix2cd d = c.tcp_frf_direct(f), r = c.tcp_frf_rcsa(f);
    worst = std::max(worst, (d - r).norm() / d.norm());
  }
  for (const auto& md : c.modes(4))
    worst = std::max(worst, (c.tcp_frf_direct(md.freq_hz) - c.tcp_frf_rcsa(md.freq_hz)).norm() /
                                c.tcp_frf_direct(md.freq_hz).norm());
  EXPECT_LT(worst, 1e-6);
  const robot::PlanarChain rigid(three_links(), q);
  EXPECT_LT(c.modes(1)[0].freq_hz, rigid.modes(1)[0].freq_hz * 0.999);  // softer
  soft.joints[0].translational_stiffness_n_per_m = soft.joints[1].translational_stiffness_n_per_m = 1e13;
  const robot::PlanarChain stiff(soft, q);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(stiff.modes(3)[i].freq_hz, rigid.modes(3)[i].freq_hz, 1e-4 * rigid.modes(3)[i].freq_hz);
  soft.joints[1].translational_stiffness_n_per_m = -1.0;
  EXPECT_THROW(robot::PlanarChain(soft, q), std::invalid_argument);
}

TEST(RobotModel, NonPhysicalModelsAndPosesAreRefusedByName) {
  auto refused = [](robot::ChainModel m, std::vector<double> q, const std::string& what) {
    try {
      const robot::PlanarChain c(std::move(m), std::move(q));
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  robot::ChainModel m = three_links();
  refused(m, {0.0, 0.0}, "2 joint angles for 3 joints");
  refused(m, {0.0, NAN, 0.0}, "joint 2 angle");
  m.links[1].mass_kg = -1.0;
  refused(m, {0.0, 0.0, 0.0}, "link 2: mass_kg");
  m = three_links();
  m.joints[2].stiffness_nm_per_rad = 0.0;
  refused(m, {0.0, 0.0, 0.0}, "joint 3: stiffness");
  m = three_links();
  m.joints.pop_back();
  refused(m, {0.0, 0.0, 0.0}, "one joint per link");
}

}  // namespace
}  // namespace robodamp

namespace robodamp {
namespace {

config::RobotModelConfig coarse_planar_robot() {
  config::RobotModelConfig m =
      config::load_robot_model(std::string(ROBODAMP_SOURCE_DIR) + "/config/robots/planar_three_link.yaml");
  for (auto& l : m.links) l.elements = std::min(l.elements, 2);  // the links are stiff: 2 elements suffice here
  return m;
}

// Particle swarm recovers the joints from synthetic TCP FRFs (yy, 10-30 Hz) with 1 % noise at the planar-robot study's
// three poses: each stiffness within 2 %, seeded and repeatable.
TEST(PoseFit, ParticleSwarmRecoversJointStiffnessesFromNoisyFrfsAtThreePoses) {
  const config::RobotModelConfig truth = coarse_planar_robot();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01 / std::sqrt(2.0));  // 1 % of |H|, complex
  std::vector<robot::MeasuredFrf> data;
  for (const auto& p : truth.poses) {
    const robot::PlanarChain c = robot::at_pose(truth, p.joints_deg);
    robot::MeasuredFrf m{p.name, p.joints_deg, {}, {}};
    for (double f = 10.0; f <= 30.0; f += 0.5) {
      const std::complex<double> h = c.tcp_frf_direct(f)(1, 1);
      m.freq_hz.push_back(f);
      m.receptance_m_per_n.push_back(h * std::complex<double>(1.0 + noise(rng), noise(rng)));
    }
    data.push_back(std::move(m));
  }
  config::RobotModelConfig start = truth;
  for (auto& j : start.joints) j.stiffness_nm_per_rad = 1e5, j.damping_ratio = 0.05;  // forgotten
  robot::PoseFitSettings s;
  s.restarts = 2;
  s.pso.particles = 24;
  s.pso.iterations = 40;
  const robot::PoseFitResult r = robot::fit_joints(start, data, s);
  for (std::size_t j = 0; j < truth.joints.size(); ++j) {
    const double k = r.stiffness_nm_per_rad[j], k0 = truth.joints[j].stiffness_nm_per_rad;
    std::cout << "joint " << j + 1 << ": " << k << " N m/rad (truth " << k0 << ", spread " << r.stiffness_spread_pct[j]
              << " %), damping " << r.damping_ratio[j] << " (truth " << truth.joints[j].damping_ratio << ")\n";
    EXPECT_NEAR(k / k0, 1.0, 0.02) << "joint " << j + 1;
  }
  for (double e : r.pose_error) EXPECT_LT(e, 0.03);
  EXPECT_GE(r.converged_restarts, 1);
  std::cout << r.converged_restarts << " of " << s.restarts << " restarts converged; " << r.evaluations
            << " evaluations\n";
  // Seeded: the same search twice gives the same numbers (a short one: repeatability, not accuracy).
  s.restarts = 1;
  s.pso.iterations = 5;
  const robot::PoseFitResult a = robot::fit_joints(start, data, s), b = robot::fit_joints(start, data, s);
  EXPECT_EQ(a.stiffness_nm_per_rad, b.stiffness_nm_per_rad);
  EXPECT_EQ(a.damping_ratio, b.damping_ratio);
}

// The modal form (robot::modal_tcp_frf): every mode of a lightly damped chain gives the assembled model's
// receptance (within 0.5 % away from the modes); the 3 lowest modes with viscous damping are the plant the emulator runs. Data from that plant
// (0.5 % noise, 400 points over 10-30 Hz) is fitted in that form to within 0.5 % per joint; the truth's own
// error is smaller in that form than in the direct one (whose hysteretic damping shifts the phase below
// each mode), which is the bias a direct fit would take into the joints.
TEST(PoseFit, TheModalFormIsThePlantsAndRecoversItsJoints) {
  config::RobotModelConfig light = coarse_planar_robot();
  for (auto& j : light.joints) j.damping_ratio = 1e-4;
  const robot::PlanarChain lc = robot::at_pose(light, light.poses[0].joints_deg);
  const std::vector<robot::Mode> all = lc.modes(lc.dofs());
  for (const double f : {5.0, 8.0, 36.0, 50.0}) {  // away from the modes (11.8, 24.2, 28.4 Hz): the 1e-3 floor apart
    const Eigen::Matrix2cd a = robot::modal_tcp_frf(all, f), b = lc.tcp_frf_direct(f);
    EXPECT_LT((a - b).norm() / b.norm(), 0.005) << f << " Hz";
  }
  const config::RobotModelConfig truth = coarse_planar_robot();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.005 / std::sqrt(2.0));
  std::vector<robot::MeasuredFrf> data;
  for (const auto& p : truth.poses) {
    const std::vector<robot::Mode> modes = robot::at_pose(truth, p.joints_deg).modes(3);
    robot::MeasuredFrf m{p.name, p.joints_deg, {}, {}};
    for (double f = 10.0; f <= 30.0; f += 0.05) {
      m.freq_hz.push_back(f);
      m.receptance_m_per_n.push_back(robot::modal_tcp_frf(modes, f)(1, 1) *
                                     std::complex<double>(1.0 + noise(rng), noise(rng)));
    }
    data.push_back(std::move(m));
  }
  robot::PoseFitSettings direct, modal;
  modal.modes = 3;
  double e_direct = 0.0, e_modal = 0.0;
  for (double e : robot::model_errors(truth, data, direct)) e_direct = std::max(e_direct, e);
  for (double e : robot::model_errors(truth, data, modal)) e_modal = std::max(e_modal, e);
  std::cout << "the truth's largest error against its own plant: " << 100.0 * e_modal << " % as modes, "
            << 100.0 * e_direct << " % as its own receptance\n";
  EXPECT_LT(e_modal, 0.006);
  EXPECT_GT(e_direct, 2.0 * e_modal);
  config::RobotModelConfig start = truth;
  for (auto& j : start.joints) j.stiffness_nm_per_rad = 1e5, j.damping_ratio = 0.05;
  modal.restarts = 2;
  modal.pso.particles = 24;
  modal.pso.iterations = 40;
  const robot::PoseFitResult r = robot::fit_joints(start, data, modal);
  for (std::size_t j = 0; j < truth.joints.size(); ++j) {
    std::cout << "joint " << j + 1 << ": " << r.stiffness_nm_per_rad[j] << " N m/rad (truth "
              << truth.joints[j].stiffness_nm_per_rad << "), damping " << r.damping_ratio[j] << "\n";
    EXPECT_NEAR(r.stiffness_nm_per_rad[j] / truth.joints[j].stiffness_nm_per_rad, 1.0, 0.005) << "joint " << j + 1;
  }
}

TEST(PoseFit, ModelFilesAndPosesAreValidatedByName) {
  const config::RobotModelConfig m = coarse_planar_robot();
  EXPECT_EQ(config::pose_problem(m, {-100.0, 120.0, -20.0}), std::nullopt);
  const auto far = config::pose_problem(m, {-100.0, 200.0, -20.0});
  ASSERT_TRUE(far.has_value());
  EXPECT_NE(far->find("joint 2 = 200 deg is out of range: allowed 0 <= value <= 170 deg"), std::string::npos) << *far;
  EXPECT_TRUE(config::pose_problem(m, {-100.0, 120.0}).has_value());
  EXPECT_TRUE(config::pose_problem(m, {-100.0, NAN, -20.0}).has_value());
  EXPECT_THROW((void)robot::at_pose(m, {-100.0, 200.0, -20.0}), config::ConfigError);
  const std::string bad =
      "links:\n  - {length_m: -1, mass_kg: 10, bending_stiffness_nm2: 1e6}\njoints:\n  - {stiffness_nm_per_rad: 0}\n"
      "  - {stiffness_nm_per_rad: 1e5}\nposes:\n  - {joints_deg: [400]}\n";
  try {
    (void)config::parse_robot_model(bad, "bad.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const config::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("links[0].length_m = -1 m is out of range"), std::string::npos) << w;
    EXPECT_NE(w.find("joints[0].stiffness_nm_per_rad = 0 N m/rad is out of range"), std::string::npos) << w;
    EXPECT_NE(w.find("2 entries for 1 links"), std::string::npos) << w;
  }
}

}  // namespace
}  // namespace robodamp

#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/sdm.hpp"
#include "milling/tool_dynamics.hpp"
#include "milling/structure.hpp"

namespace robodamp {
namespace {

// A milling job whose structure is the robot model at a pose (config/milling/planar_three_link_pose2.yaml): the
// structure's FRF is the model's TCP receptance, the lobes and the direct test agree, another pose moves the
// low modes' lobes, and the time-domain cut refuses it by name.
TEST(PoseLobes, AJobAtAPoseTakesTheRobotModelsTcpReceptance) {
  config::MillingConfig job =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/planar_three_link_pose2.yaml");
  job.lobes.points = 400;  // enough for the check, a fifth of the job's cost
  job.lobes.points_per_mode = 80;
  const auto& part = *job.structures.front().parts.front().pose;
  const config::RobotModelConfig model = config::load_robot_model(part.model_path);
  const robot::PlanarChain chain = robot::at_pose(model, part.joints_deg);
  const milling::Structure s(job.structures.front(), false);
  for (const double f : {5.0, 11.6, 23.0, 120.0}) EXPECT_LT((s.frf(f) - chain.tcp_frf_direct(f)).norm(), 1e-15) << f;
  const auto process = milling::chatter_process(job.tool, job.material, job.cut);
  const milling::LobeModel lobes(s, process, job.lobes);
  const auto d = lobes.diagram();
  const double direct = lobes.critical_depth_mm(d.minimum.rpm);
  std::cout << "pose 2: minimum " << d.minimum.b_lim_mm << " mm at " << d.minimum.rpm << " rpm, chatter "
            << d.minimum.chatter_hz << " Hz; direct test " << direct * 1e3 << " mm\n";
  EXPECT_NEAR(direct / d.minimum.b_lim_mm, 1.0, 0.01);
  EXPECT_GT(d.minimum.chatter_hz, 5.0);
  EXPECT_LT(d.minimum.chatter_hz, 40.0) << "the minimum is set by the joints' modes";
  // Pose 1 (stiffer): a higher minimum.
  config::StructureConfig at1 = job.structures.front();
  at1.parts.front().pose->joints_deg = model.poses.front().joints_deg;
  const milling::Structure s1(at1, false);
  EXPECT_GT(milling::LobeModel(s1, process, job.lobes).diagram().minimum.b_lim_mm, d.minimum.b_lim_mm);
  // The cut in time takes the model's lowest modes (mass-normalised shapes): they reproduce its TCP
  // receptance at the joints' modes, and the simulated cut's critical depth where a joint mode limits
  // agrees with SDM on the same terms and with the zero-order lobes of the exact receptance.
  const milling::CutJob cut = milling::make_cut_job(job, s, {});
  const auto terms = milling::cutter_modal_terms(s, config::Axis::kX);  // machine frame
  for (const double f : {11.604, 23.185, 26.973}) {
    Eigen::Matrix2cd h = Eigen::Matrix2cd::Zero();
    const std::complex<double> jw(0.0, 2.0 * M_PI * f);
    for (const auto& t : terms)
      h(t.response, t.excitation) +=
          (t.a + t.b * jw) / (jw * jw + 2.0 * t.damping_ratio * t.wn_rad_per_s * jw + t.wn_rad_per_s * t.wn_rad_per_s);
    const Eigen::Matrix2cd exact = chain.tcp_frf_direct(f);
    std::cout << f << " Hz: modal terms against the model " << (h - exact).norm() / exact.norm() << " relative\n";
    // The joints' damping is not proportional (zeta 0.02, 0.02, 0.01): undamped shapes with modal damping
    // are within 1.4-5.8 % of the exact receptance at the three peaks.
    EXPECT_NEAR((h - exact).norm() / exact.norm(), 0.0, 0.08) << f << " Hz";
  }
  constexpr double rpm = 526.0;
  milling::CutOverrides ov;
  ov.rpm = rpm;
  const milling::CutJob at = milling::make_cut_job(job, s, ov);
  const double zoa_mm = lobes.critical_depth_mm(rpm);
  const milling::SdmPoint sdm =
      milling::SdmModel(at.terms, at.cutter, at.material, job.cut.mode, job.cut.radial_mm, 1, 40).critical(rpm, zoa_mm);
  const milling::CriticalDepth td =
      milling::critical_depth(at.dynamics, at.cutter, at.material, at.settings, sdm.critical_depth_mm);
  std::cout << "pose 2 at " << rpm << " rpm: zero-order " << zoa_mm << " mm, SDM " << sdm.critical_depth_mm
            << " mm, time domain " << td.depth_mm << " mm (chatter " << td.chatter_hz << " Hz)\n";
  EXPECT_GT(cut.terms.size(), 12U);
  // Measured: zero-order 0.0357, SDM 0.0369, time domain 0.0387 mm. The simulated cut keeps the job's
  // helix, runout and the tool leaving the cut, which SDM's linear model does not (at 1500 rpm the soft
  // joints' forced vibration already takes the tool out of the cut: 0.201 mm against SDM's 0.243).
  EXPECT_NEAR(td.depth_mm / sdm.critical_depth_mm, 1.0, 0.08);
  EXPECT_NEAR(td.depth_mm / zoa_mm, 1.0, 0.12);
  EXPECT_NEAR(td.chatter_hz, 27.3, 2.0);
  // A pose outside the travel in the job file is refused when the job is read.
  std::string text = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/planar_three_link_pose2.yaml");
  text.replace(text.find("119.81"), 6, "200.00");
  try {
    (void)config::parse_milling_config(text, "pose.yaml", std::string(ROBODAMP_SOURCE_DIR) + "/config/milling");
    ADD_FAILURE() << "accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("joint 2 = 200 deg is out of range"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace robodamp
