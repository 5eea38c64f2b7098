// SDM on its structure (issue 57): the interval's exponential by structured products with balancing against
// Eigen's dense scaling and squaring, the open-loop semi-discretization of the 46-mode industrial robot
// against the dense formula it replaced, and the dominant multiplier by Arnoldi against the dense QR
// (docs/milling.md, "How fast"): the same multipliers and depths.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "config/milling_config.hpp"
#include "milling/dominant_multiplier.hpp"
#include "milling/interval_collocation.hpp"
#include "milling/interval_exp.hpp"
#include "milling/sdm.hpp"
#include "milling/structure.hpp"
#include "milling/tool_dynamics.hpp"
#include "units/units.hpp"

namespace {

using namespace robodamp;
using namespace robodamp::milling;

struct Robot {
  config::MillingConfig job;
  std::vector<CutterModalTerm> terms;
};

const Robot& industrial_robot() {
  static const Robot r = [] {
    Robot out{config::load_milling_config(
                  std::string(ROBODAMP_SOURCE_DIR).append("/config/milling/industrial_robot_aluminium.yaml")),
              {}};
    out.terms = cutter_modal_terms(Structure(out.job.selected_structure(), false), out.job.cut.feed_axis);
    return out;
  }();
  return r;
}

// The dense first-order SDM as it was written before the structured one (Insperger and Stepan 2004):
// the augmented interval matrix's exponential by Eigen, the monodromy by dense products.
std::complex<double> dense_multiplier(const Robot& r, double axial_mm, double rpm, int m) {
  const ToolDynamics dyn(r.terms, 1.0);
  const Eigen::MatrixXd &a = dyn.a(), &b = dyn.b(), &c = dyn.c();
  const Cutter cutter = cutter_from(r.job.tool);
  const Eigen::Index n = a.rows(), d = n + 2 * m;
  const double h = 60.0 / (rpm * cutter.teeth) / m;
  Eigen::MatrixXd z = Eigen::MatrixXd::Identity(d, d), next(d, d), big = Eigen::MatrixXd::Zero(n + 4, n + 4);
  const DirectionalMatrix directional(cutter, r.job.material, r.job.cut.mode, r.job.cut.radial_mm,
                                      r.job.time_domain.axial_slices, axial_mm);
  const double dphi = kTwoPi / (cutter.teeth * m);
  for (int i = 0; i < m; ++i) {
    const Eigen::Matrix2d mi = directional.mean(i * dphi, dphi, 8);
    big.setZero();
    big.topLeftCorner(n, n) = a + b * mi * c;
    big.block(0, n, n, 2) = -b * mi;
    big.block(n, n + 2, 2, 2).setIdentity();
    const Eigen::MatrixXd e = (big * h).exp();
    const Eigen::MatrixXd phi = e.topLeftCorner(n, n), held = e.block(0, n, n, 2), ramp = e.block(0, n + 2, n, 2) / h;
    const Eigen::MatrixXd old_x = z.topRows(n), q_oldest = z.middleRows(n + 2 * (m - 1), 2),
                          q_next = z.middleRows(n + 2 * (m - 2), 2);
    next.topRows(n) = phi * old_x + (held - ramp) * q_oldest + ramp * q_next;
    next.middleRows(n, 2) = c * old_x;
    next.middleRows(n + 2, 2 * (m - 1)) = z.middleRows(n, 2 * (m - 1));
    z.swap(next);
  }
  const Eigen::VectorXcd ev = Eigen::EigenSolver<Eigen::MatrixXd>(z, false).eigenvalues();
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < ev.size(); ++i)
    if (std::abs(ev(i)) > std::abs(ev(best))) best = i;
  return ev(best);
}

TEST(IntervalExp, EqualsTheDenseExponentialOverTheSpeedsAndCutsOfTheIndustrialRobot) {
  const Robot& r = industrial_robot();
  const ToolDynamics dyn(r.terms, 1.0);
  const Eigen::Index n = dyn.a().rows();
  // The blocks as the structure has them ((q, q'): norm ~wn^2) and a cut of 1e5-1e8 N/m: the worst scaling.
  std::vector<Eigen::Matrix2d> blocks;
  for (Eigen::Index k = 0; k < n; k += 2) blocks.emplace_back(dyn.a().block(k, k, 2, 2));
  IntervalExp structured(blocks, dyn.c());
  Eigen::MatrixXd e;
  for (const double h_s : {2e-6, 5e-5, 4e-4, 3e-3}) {
    for (const double stiffness_n_per_m : {1e5, 3e6, 1e8}) {
      const Eigen::Matrix2d m = stiffness_n_per_m * (Eigen::Matrix2d() << 0.9, -0.4, 0.7, 0.2).finished();
      const Eigen::MatrixXd u = dyn.b() * m;
      Eigen::MatrixXd big = Eigen::MatrixXd::Zero(n + 4, n + 4);
      big.topLeftCorner(n, n) = dyn.a() + u * dyn.c();
      big.block(0, n, n, 2) = -u;
      big.block(n, n + 2, 2, 2).setIdentity();
      // The truth in long double (Eigen's scaling and squaring at 64-bit precision).
      using MatrixXld = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
      const Eigen::MatrixXd truth =
          MatrixXld((big.cast<long double>() * static_cast<long double>(h_s)).exp()).cast<double>();
      const Eigen::MatrixXd dense = (big * h_s).exp();
      structured.compute(u, h_s, e);
      // Entry by entry against the entries' own scale (rows and columns mix metres, m/s and N/m).
      const Eigen::VectorXd row = truth.cwiseAbs().rowwise().maxCoeff(), col = truth.cwiseAbs().colwise().maxCoeff();
      auto error = [&](const Eigen::MatrixXd& x) {
        double worst = 0.0;
        for (Eigen::Index i = 0; i < x.rows(); ++i)
          for (Eigen::Index j = 0; j < x.cols(); ++j)
            worst = std::max(worst, std::abs(x(i, j) - truth(i, j)) / std::sqrt(row(i) * col(j) + 1e-300));
        return worst;
      };
      // Measured: 8e-16 to 8e-10 structured, 4e-13 to 6e-6 dense (its 10-20 more squarings).
      EXPECT_LT(error(e), 5e-9) << "h " << h_s << " s, cut " << stiffness_n_per_m << " N/m, " << structured.squarings()
                                << " squarings";
      EXPECT_LE(error(e), error(dense)) << "h " << h_s << " s, cut " << stiffness_n_per_m << " N/m";
    }
  }
  // Without cutting: each mode's own exponential.
  const std::vector<Eigen::Matrix2d> free = structured.free_blocks(4e-4);
  for (std::size_t k = 0; k < blocks.size(); ++k)
    EXPECT_LT((free[k] - (blocks[k] * 4e-4).exp()).norm(), 1e-12 * (1.0 + free[k].norm()));
}

// One cutting interval of the 46-mode robot by collocation against the structured dense exponential (itself
// within 8e-10 of the long-double truth above): the map of the modes' state and the two delayed samples,
// entry by entry against the entries' scale, at the interval lengths of 15 000 to 700 rpm (40 steps, three
// teeth) and cuts of 1e5 to 1e8 N/m, wherever the node rule takes it (up to n / 2 nodes, 46 here).
TEST(IntervalCollocation, EqualsTheDenseExponentialsMapOnTheIndustrialRobotsShortIntervals) {
  const Robot& r = industrial_robot();
  const ToolDynamics dyn(r.terms, 1.0);
  const Eigen::Index n = dyn.a().rows();
  // The blocks in the (wn q, q') form SdmModel takes.
  Eigen::MatrixXd a = dyn.a(), b = dyn.b(), c = dyn.c();
  for (Eigen::Index k = 0; k < n; k += 2) {
    const double wn = std::sqrt(-a(k + 1, k));
    a(k, k + 1) = wn, a(k + 1, k) = -wn, b.row(k) *= wn, c.col(k) /= wn;
  }
  std::vector<Eigen::Matrix2d> blocks;
  for (Eigen::Index k = 0; k < n; k += 2) blocks.emplace_back(a.block(k, k, 2, 2));
  IntervalExp dense(blocks, c);
  int checked = 0;
  for (const double rpm : {15000.0, 10700.0, 5000.0, 2500.0, 1156.0, 700.0}) {
    const double h = 60.0 / (rpm * 3) / 40;
    for (const double stiffness_n_per_m : {1e5, 3e6, 1e8}) {
      const Eigen::Matrix2d m = stiffness_n_per_m * (Eigen::Matrix2d() << 0.9, -0.4, 0.7, 0.2).finished();
      double rho = 0.0;
      for (const Eigen::Matrix2d& blk : blocks) rho = std::max(rho, blk.operatorNorm());
      rho += (b * m * c).operatorNorm();
      const int p = IntervalCollocation::nodes_for(rho * h);
      if (p == 0 || 2 * p > n) continue;  // SdmModel takes the dense exponential there
      ++checked;
      IntervalCollocation colloc(blocks, b, c, h, p, dense.free_blocks(h));
      colloc.set_cut(m);
      Eigen::MatrixXd e;
      dense.compute(b * m, h, e);
      // The map of [x; q_o; q_no] as SdmModel applies it: the ramp from q_o to q_no over the interval.
      Eigen::MatrixXd truth(n, n + 4), got(n, n + 4);
      truth.leftCols(n) = e.topLeftCorner(n, n);
      truth.middleCols(n, 2) = e.block(0, n, n, 2) - e.block(0, n + 2, n, 2) / h;
      truth.rightCols(2) = e.block(0, n + 2, n, 2) / h;
      Eigen::MatrixXd unit = Eigen::MatrixXd::Identity(n + 4, n + 4);
      colloc.step(unit.topRows(n), unit.middleRows(n, 2), unit.bottomRows(2), got);
      const Eigen::VectorXd row = truth.cwiseAbs().rowwise().maxCoeff(), col = truth.cwiseAbs().colwise().maxCoeff();
      double worst = 0.0;
      for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = 0; j < n + 4; ++j)
          worst = std::max(worst, std::abs(got(i, j) - truth(i, j)) / std::sqrt(row(i) * col(j) + 1e-300));
      // Measured: 2e-15 to 4e-15 (the node rule is conservative: two thirds of its nodes still give 5e-15).
      EXPECT_LT(worst, 1e-12) << rpm << " rpm, " << stiffness_n_per_m << " N/m, " << p << " nodes";
    }
  }
  // Every speed at 1e5 N/m (13-44 nodes), all but 700 rpm at 3e6 N/m (15-43) and 15 000 rpm at 1e8 N/m (42).
  EXPECT_EQ(checked, 12);
}

TEST(Sdm, TheLowRankIntervalsGiveTheDenseIntervalsMultipliersAndDepthsOnTheFortySixModeRobot) {
  const Robot& r = industrial_robot();
  const Cutter cutter = cutter_from(r.job.tool);
  const int m = r.job.time_domain.sdm_steps_per_period;
  const SdmModel fast(r.terms, cutter, r.job.material, r.job.cut.mode, r.job.cut.radial_mm,
                      r.job.time_domain.axial_slices, m);
  SdmModel reference = fast;
  reference.dense_intervals_only();
  for (const double rpm : {700.0, 1156.0, 2100.0, 4321.0, 8000.0, 10700.0, 14900.0})
    for (const double axial_mm : {0.5, 2.0, 6.0, 40.0}) {
      const std::complex<double> truth = reference.multiplier(axial_mm, rpm), got = fast.multiplier(axial_mm, rpm);
      EXPECT_NEAR(std::abs(got), std::abs(truth), 1e-9 * std::abs(truth)) << rpm << " rpm, " << axial_mm << " mm";
      EXPECT_NEAR(std::abs(std::arg(got)), std::abs(std::arg(truth)), 1e-8) << rpm << " rpm, " << axial_mm << " mm";
    }
  for (const double rpm : {1156.0, 6500.0, 10700.0}) {
    const SdmPoint truth = reference.critical(rpm, 3.0), got = fast.critical(rpm, 3.0);
    EXPECT_NEAR(got.critical_depth_mm, truth.critical_depth_mm, 1e-6 * truth.critical_depth_mm) << rpm << " rpm";
    EXPECT_NEAR(got.chatter_hz, truth.chatter_hz, 1e-6 * truth.chatter_hz) << rpm << " rpm";
    EXPECT_EQ(got.type, truth.type) << rpm << " rpm";
  }
}

TEST(Sdm, TheStructuredMonodromyHasTheDenseFormulasMultipliersAndDepthsOnTheFortySixModeRobot) {
  const Robot& r = industrial_robot();
  ASSERT_EQ(r.terms.size(), 46U);
  const Cutter cutter = cutter_from(r.job.tool);
  const int m = r.job.time_domain.sdm_steps_per_period;
  const SdmModel sdm(r.terms, cutter, r.job.material, r.job.cut.mode, r.job.cut.radial_mm,
                     r.job.time_domain.axial_slices, m);
  // The diagram's minimum (1156 rpm), a middle speed and the published job's 10 700 rpm; a stable and an
  // unstable depth at each.
  for (const double rpm : {1156.0, 5000.0, 10700.0})
    for (const double axial_mm : {3.0, 12.0}) {
      const std::complex<double> truth = dense_multiplier(r, axial_mm, rpm, m), got = sdm.multiplier(axial_mm, rpm);
      // The dense formula's own exponential is the less accurate one (IntervalExp's test): 1e-8 apart.
      EXPECT_NEAR(std::abs(got), std::abs(truth), 1e-8 * std::abs(truth)) << rpm << " rpm, " << axial_mm << " mm";
      // Either of a complex pair (the matrix is real): the same multiplier.
      EXPECT_NEAR(std::abs(std::arg(got)), std::abs(std::arg(truth)), 1e-7) << rpm << " rpm, " << axial_mm << " mm";
    }
  // The critical depth: the same search on the same function gives the same bracket.
  const DepthBracket truth =
      find_critical_depth([&](double b) { return std::log(std::abs(dense_multiplier(r, b, 1156.0, m))); }, 3.0, 1e-3);
  const SdmPoint got = sdm.critical(1156.0, 3.0);
  EXPECT_NEAR(got.critical_depth_mm, truth.lo_mm, 1e-7 * truth.lo_mm);
  EXPECT_NEAR(got.critical_depth_mm, 3.478, 0.0005);  // docs/tests.md's minimum of the 200-speed diagram
  EXPECT_NEAR(got.chatter_hz, 28.9, 0.05);
}

}  // namespace

namespace {

// A real matrix of this size with the given multipliers (complex ones with their conjugates), the rest of its
// spectrum random inside radius `rest`, in a random basis (condition number 3).
Eigen::MatrixXd with_spectrum(Eigen::Index size, const std::vector<std::complex<double>>& wanted, double rest,
                              unsigned seed) {
  std::srand(seed);
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(size, size);
  Eigen::Index i = 0;
  auto place = [&](std::complex<double> mu) {
    if (mu.imag() == 0.0) {
      d(i, i) = mu.real(), i += 1;
      return;
    }
    d(i, i) = d(i + 1, i + 1) = mu.real();
    d(i, i + 1) = mu.imag(), d(i + 1, i) = -mu.imag();
    i += 2;
  };
  for (const auto& mu : wanted) place(mu);
  while (i + 1 < size) {
    const Eigen::Vector2d u = Eigen::Vector2d::Random();
    place(std::polar(rest * std::abs(u(0)), 3.0 * u(1)));
  }
  if (i < size) place({0.5 * rest, 0.0});
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(size, size)).householderQ();
  const Eigen::VectorXd scale = Eigen::VectorXd::LinSpaced(size, 1.0, 3.0);
  const Eigen::MatrixXd v = q * scale.asDiagonal(), v_inv = scale.cwiseInverse().asDiagonal() * q.transpose();
  return v * d * v_inv;
}

}  // namespace

TEST(DominantMultiplier, ArnoldiFindsTheLargestWhereFewMultipliersAreNearTheCircleAsTheDenseQrDoes) {
  // A Hopf pair just outside the circle over a flip multiplier and a pair inside, the other 143 inside 0.6.
  const std::complex<double> hopf = std::polar(1.004, 0.4);
  const Eigen::MatrixXd z = with_spectrum(150, {std::polar(0.97, 2.0), -0.99, hopf}, 0.6, 7);
  DominantMultiplier largest;
  const std::complex<double> got = largest(z);
  EXPECT_NEAR(std::abs(got), std::abs(hopf), 1e-11);
  EXPECT_NEAR(std::abs(got.imag()), hopf.imag(), 1e-11);
  EXPECT_NEAR(std::abs(got), std::abs(dense_dominant_multiplier(z)), 1e-11);
  EXPECT_EQ(largest.arnoldi_answers(), 1);
  EXPECT_EQ(largest.dense_answers(), 0);
  // A flip: the real negative one the largest.
  const Eigen::MatrixXd flip = with_spectrum(150, {std::polar(0.97, 2.0), -1.01, std::polar(0.995, 0.4)}, 0.6, 8);
  const std::complex<double> f = largest(flip);
  EXPECT_NEAR(f.real(), -1.01, 1e-11);
  EXPECT_NEAR(f.imag(), 0.0, 1e-11);
  EXPECT_EQ(largest.arnoldi_answers(), 2);
}

// The critical Floquet mode's vector by inverse iteration (eigenvector_for) is the dense QR's vector up to a
// complex factor: on a crowded spectrum (60 pairs between 0.97 and 0.99), a nearly real pair (the conjugate
// 2e-6 away) and a flip. (The 46-mode robot's chatter frequency at 1156 rpm, from this vector now, is held above:
// 28.9 Hz.)
TEST(DominantMultiplier, TheEigenvectorByInverseIterationIsTheDenseQrsVector) {
  std::vector<std::complex<double>> crowd;
  for (int k = 0; k < 60; ++k) crowd.push_back(std::polar(0.97 + 0.02 * k / 59.0, 0.05 + 3.0 * k / 60.0));
  const std::vector<Eigen::MatrixXd> cases = {with_spectrum(172, crowd, 0.5, 12),
                                              with_spectrum(150, {std::polar(1.003, 1e-6), 0.99}, 0.6, 13),
                                              with_spectrum(150, {-1.01, std::polar(0.995, 0.4)}, 0.6, 14)};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Eigen::MatrixXd& z = cases[c];
    const std::complex<double> mu = dense_dominant_multiplier(z);
    const Eigen::VectorXcd v = eigenvector_for(z, mu);
    EXPECT_NEAR(v.norm(), 1.0, 1e-12) << c;
    EXPECT_LT((z.cast<std::complex<double>>() * v - mu * v).norm(), 1e-10) << "the residual, case " << c;
    const Eigen::EigenSolver<Eigen::MatrixXd> es(z, true);
    Eigen::Index best = 0;
    for (Eigen::Index i = 1; i < z.rows(); ++i)
      if (std::abs(es.eigenvalues()(i) - mu) < std::abs(es.eigenvalues()(best) - mu)) best = i;
    const Eigen::VectorXcd d = es.eigenvectors().col(best).normalized();
    EXPECT_NEAR(std::abs(d.dot(v)), 1.0, 1e-9) << "parallel to the dense QR's vector, case " << c;
  }
}

TEST(DominantMultiplier, WhereTheyCrowdTheCircleArnoldiOnTheEighthPowerAnswersElseTheDenseQr) {
  // 46 pairs between 0.93 and 0.99 (the many lightly damped modes of a long structure over a short period):
  // Arnoldi on z does not converge within its restarts; on z^8 the top moduli are 1.1 % apart instead of
  // 0.13 %, it converges, and its vector's Rayleigh quotient in z is the dense QR's multiplier, its argument too.
  std::vector<std::complex<double>> crowd;
  for (int k = 0; k < 46; ++k) crowd.push_back(std::polar(0.93 + 0.06 * k / 45.0, 0.05 + 3.0 * k / 46.0));
  const Eigen::MatrixXd z = with_spectrum(172, crowd, 0.5, 9);
  DominantMultiplier largest;
  const std::complex<double> got = largest(z), dense = dense_dominant_multiplier(z);
  EXPECT_NEAR(std::abs(got), 0.99, 1e-11);
  EXPECT_NEAR(std::abs(got - (dense.imag() * got.imag() < 0.0 ? std::conj(dense) : dense)), 0.0, 1e-11);
  EXPECT_EQ(largest.arnoldi_answers(), 0);
  EXPECT_EQ(largest.powered_answers(), 1);
  EXPECT_EQ(largest.dense_answers(), 0);
  const Eigen::MatrixXd easy = with_spectrum(150, {std::polar(1.004, 0.4)}, 0.6, 10);
  EXPECT_NEAR(std::abs(largest(easy)), 1.004, 1e-11);
  EXPECT_EQ(largest.arnoldi_answers(), 0) << "the search that crowded stays with the powered Arnoldi";
  EXPECT_EQ(largest.powered_answers(), 2);
  // 60 pairs between 0.97 and 0.99: 0.03 % apart at the top, 0.3 % in z^8; neither Arnoldi converges, the
  // dense QR answers, and the rest of the search goes there at once.
  crowd.clear();
  for (int k = 0; k < 60; ++k) crowd.push_back(std::polar(0.97 + 0.02 * k / 59.0, 0.05 + 3.0 * k / 60.0));
  const Eigen::MatrixXd tight = with_spectrum(172, crowd, 0.5, 9);
  DominantMultiplier search;
  const std::complex<double> t = search(tight);
  EXPECT_NEAR(std::abs(t), 0.99, 1e-11);
  EXPECT_EQ(t, dense_dominant_multiplier(tight));
  EXPECT_EQ(search.arnoldi_answers() + search.powered_answers(), 0);
  EXPECT_EQ(search.dense_answers(), 1);
  EXPECT_NEAR(std::abs(search(easy)), 1.004, 1e-11);
  EXPECT_EQ(search.dense_answers(), 2);
  // A small matrix: the dense QR.
  DominantMultiplier small;
  EXPECT_NEAR(std::abs(small(with_spectrum(40, {std::polar(0.9, 1.0)}, 0.5, 11))), 0.9, 1e-12);
  EXPECT_EQ(small.dense_answers(), 1);
}
