// The plant's per-tick kernel (issue 14): the modal block form against the dense exact discretisation it
// replaces, the merged realisation against the per-path modal sums, the drive vibration's phase
// recurrence against the exact phase, and the inline quantisation against std::round.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "analysis/loop_model.hpp"
#include "sim_plant/excitation.hpp"
#include "sim_plant/modal_step.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/sensor.hpp"
#include "test_util.hpp"

namespace {

using namespace robodamp;

// Three locations, one of them (the actuator's) with its own driving point, so that there are driven
// and free blocks at two force locations and the realisation merges the modes the paths share.
sim::PlantModel preset_model(const std::string& name) {
  return sim::build_plant_model(config::load_config_file(test::preset(name)));
}

TEST(ModalStep, MatchesTheDenseDiscretisationStepForStep) {
  for (const char* name : {"horizontal_c2", "vertical_c1"}) {
    const sim::PlantModel m = preset_model(name);
    const double h = 1.0 / 5000.0;
    const auto nl = m.ss.b.cols() - 1;
    const sim::DelayedZoh coil = sim::discretise_zoh_delayed(m.ss.a, m.ss.b.leftCols(1), h / 4, m.actuator.delay_s);
    const sim::Zoh forces = sim::discretise_zoh(m.ss.a, m.ss.b.rightCols(nl), h / 4);
    sim::ModalStep step(m.ss, coil, forces.gamma);
    ASSERT_EQ(step.states(), static_cast<std::size_t>(m.ss.a.rows()));
    sim::Vector x = sim::Vector::Zero(m.ss.a.rows());
    std::mt19937_64 rng(3);
    std::normal_distribution<double> n;
    double worst = 0.0, scale = 0.0, worst_out = 0.0, scale_out = 0.0;
    sim::Vector u(1 + nl);
    for (int k = 0; k < 20000; ++k) {
      const double late = n(rng), early = n(rng);
      sim::Vector f(nl);
      for (Eigen::Index l = 0; l < nl; ++l) f(l) = 100.0 * n(rng);
      step.advance(late, early, f.data());
      x = coil.phi * x + coil.gamma_late.col(0) * late + coil.gamma_early.col(0) * early + forces.gamma * f;
      worst = std::max(worst, (step.state() - x).cwiseAbs().maxCoeff());
      scale = std::max(scale, x.cwiseAbs().maxCoeff());
      u << late, f;
      const sim::Vector y = m.ss.c * x + m.ss.d * u;
      for (Eigen::Index r = 0; r < y.size(); ++r) {
        worst_out = std::max(worst_out, std::abs(step.output(static_cast<std::size_t>(r), u.data()) - y(r)));
        scale_out = std::max(scale_out, std::abs(y(r)));
      }
    }
    EXPECT_LT(worst, 1e-12 * scale) << name;
    EXPECT_LT(worst_out, 1e-12 * scale_out) << name;
  }
}

TEST(PlantModel, PathsThatShareAModeShareItsBlock) {
  const sim::PlantModel m = preset_model("horizontal_c2");
  // H11 (excited at 1) and H21 (excited at 1) share only the 23.5 Hz mode (their 9.2 and 21 Hz damping
  // differs): 5 blocks at location 1; H22 and the reciprocal H12 (excited at 2) share all three: 3 blocks.
  EXPECT_EQ(m.ss.a.rows(), 2 + 2 * (5 + 3));
  // The realisation's receptances are the paths' modal sums (Eq. 1) at every pair of locations.
  const Eigen::Index n = m.ss.a.rows(), nl = static_cast<Eigen::Index>(m.locations.size());
  for (double f : {2.0, 9.2, 15.0, 23.5, 80.0}) {
    const std::complex<double> s(0.0, 2.0 * M_PI * f);
    const Eigen::MatrixXcd h = m.ss.c.topRows(nl).cast<std::complex<double>>() *
                               (s * Eigen::MatrixXcd::Identity(n, n) - m.ss.a.cast<std::complex<double>>())
                                   .partialPivLu()
                                   .solve(m.ss.b.rightCols(nl).cast<std::complex<double>>());
    for (Eigen::Index r = 0; r < nl; ++r)
      for (Eigen::Index e = 0; e < nl; ++e) {
        const auto want = m.receptance(static_cast<std::size_t>(r), static_cast<std::size_t>(e), f);
        EXPECT_LT(std::abs(h(r, e) - want), 1e-9 * std::abs(want) + 1e-18) << f << " Hz H" << r + 1 << e + 1;
      }
  }
}

TEST(Excitation, SinePhaseRecurrenceStaysOnTheExactPhase) {
  const double a = 12.5, f = 3.0, phase = 0.7, h = 1.0 / 20000.0;
  sim::Sine sine(0, a, f, phase);
  // Reference in long double: the difference of two close cosines cancels, and at a large t the phase's
  // own rounding in double (|w t| x 1e-16 rad) divided by w h sets how close any double evaluation can be.
  auto exact = [&](double t0, double t1) {
    const long double wl = 2.0L * 3.14159265358979323846264338327950288L * f;
    return static_cast<double>(a * (std::cos(wl * t0 + phase) - std::cos(wl * t1 + phase)) / (wl * (t1 - t0)));
  };
  double worst = 0.0;
  const long steps = 2000000;  // 100 s
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * h;
    worst = std::max(worst, std::abs(sine.force_n(t, h) - exact(t, t + h)));
  }
  EXPECT_LT(worst, 1e-9 * a);
  // A jump in time, and another step length, are evaluated directly (|w t| = 2.3e4 rad here: the phase's
  // rounding alone gives ~1e-8 of the amplitude).
  EXPECT_NEAR(sine.force_n(1234.5678, h), exact(1234.5678, 1234.5678 + h), 1e-7 * a);
  EXPECT_NEAR(sine.force_n(1234.5678 + h, 4 * h), exact(1234.5678 + h, 1234.5678 + 5 * h), 1e-7 * a);
}

TEST(Sensor, QuantisationRoundsHalfAwayFromZeroLikeStdRound) {
  config::SensorConfig s;
  s.noise_density_ug_per_rthz = 0.0;
  s.highpass_hz = 0.0;
  s.adc_bits = 12;
  sim::Accelerometer sensor(s, 5000.0, 1);
  const double lsb = sensor.lsb_mps2();
  for (int k = -6; k <= 6; ++k) {
    const double tie = (k + 0.5) * lsb;
    EXPECT_EQ(sensor.measure(tie), std::round(tie / lsb) * lsb) << k;
    EXPECT_EQ(sensor.measure(-tie), std::round(-tie / lsb) * lsb) << k;
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.9 * sensor.range_mps2(), 0.9 * sensor.range_mps2());
  for (int i = 0; i < 100000; ++i) {
    const double a = u(rng);
    ASSERT_EQ(sensor.measure(a), std::round(a / lsb) * lsb) << a;
  }
}

}  // namespace
