// Pose-dependent robot dynamics (robot/): the beam element against Euler-Bernoulli's cantilever, the
// receptance coupling against the assembled model, seed 002's preset at its three poses.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "robot/planar_chain.hpp"

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
    std::cout << "mode " << i + 1 << ": " << modes[static_cast<std::size_t>(i)].freq_hz << " Hz, Euler-Bernoulli " << exact << " Hz\n";
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
  // Reciprocity: the assembled TCP receptance is symmetric.
  const Eigen::Matrix2cd g = c.tcp_frf_direct(12.0);
  EXPECT_LT(std::abs(g(0, 1) - g(1, 0)) / std::abs(g(0, 0)), 1e-9);
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
