// Continuous blocks against closed-form values and the published phases at 9.2 Hz (docs/physics.md s. 1).
#include <gtest/gtest.h>

#include <cmath>

#include "filters/transfer_function.hpp"

namespace robodamp::filters {
namespace {

constexpr double kRobotModeHz = 9.2;

double phase_at(const TransferFunction& tf, double f) { return phase_deg(tf.at_hz(f)); }

TEST(TransferFunction, PublishedPhasesAtTheRobotMode) {
  EXPECT_NEAR(phase_at(compensator_c1(9.0, 0.15, 0.5, 1.0), kRobotModeHz), -75.44, 0.01);
  EXPECT_NEAR(phase_at(compensator_c2(), kRobotModeHz), 34.3, 0.05);
  EXPECT_NEAR(phase_at(compensator_c3(), kRobotModeHz), 48.0, 0.05);
  EXPECT_NEAR(phase_at(highpass2(4.0, 0.707), kRobotModeHz), 37.0, 0.5);
  EXPECT_NEAR(phase_at(notch(3.0, 4.0), kRobotModeHz), 26.0, 0.5);
  EXPECT_NEAR(phase_at(lowpass2(50.0, 0.707) * lowpass2(50.0, 0.707), kRobotModeHz), -30.1, 0.05);
}

TEST(TransferFunction, TheCorrectionsMatter) {
  // As printed, C1 with z_c = z_a = 0.15 misses the stated phase; C2 with 2111101 misses too.
  EXPECT_GT(std::abs(phase_at(compensator_c1(9.0, 0.15, 0.5, 0.15), kRobotModeHz) + 75.44), 1.0);
  const TransferFunction c2_printed(Polynomial::from_descending({3.0, 413.7, 17241.0, 2111101.0}),
                                    Polynomial::from_descending({1.004, 1254.0, 98360.0, 186300.0}));
  EXPECT_GT(std::abs(phase_at(c2_printed, kRobotModeHz) - 34.3), 1.0);
}

TEST(TransferFunction, ClosedFormBlockValues) {
  EXPECT_NEAR(std::abs(lowpass2(50.0, 0.707).at_hz(1e-6)), 1.0, 1e-12);
  EXPECT_NEAR(magnitude_db(lowpass2(50.0, std::sqrt(0.5)).at_hz(50.0)), -3.0103, 1e-3);
  EXPECT_NEAR(phase_at(lowpass2(50.0, 0.3), 50.0), -90.0, 1e-9);
  EXPECT_NEAR(phase_at(highpass2(4.0, 0.3), 4.0), 90.0, 1e-9);
  EXPECT_LT(std::abs(notch(3.0, 4.0).at_hz(3.0)), 1e-12);  // zeros on the j-axis
  // Notch -3 dB points are a apart (Eq. 14: bandwidth a in Hz).
  const double w0 = 3.0, a = 4.0;
  const double f_lo = (-a + std::sqrt(a * a + 4 * w0 * w0)) / 2, f_hi = f_lo + a;
  EXPECT_NEAR(magnitude_db(notch(w0, a).at_hz(f_lo)), -3.0103, 1e-3);
  EXPECT_NEAR(magnitude_db(notch(w0, a).at_hz(f_hi)), -3.0103, 1e-3);
  EXPECT_NEAR(phase_at(integrator(), 7.0), -90.0, 1e-12);
  EXPECT_NEAR(std::abs(integrator().at_hz(1.0)), 1.0 / kTwoPi, 1e-15);
  // Actuator (Eq. 3) is flat at T in its 30-120 Hz band.
  EXPECT_NEAR(std::abs(actuator(4.8, 9.0, 0.15).at_hz(100.0)), 4.8, 0.05);
}

TEST(TransferFunction, IntegratorTimesHighpassCancelsExactly) {
  const TransferFunction pair = integrator() * highpass2(4.0, 0.707);
  EXPECT_EQ(pair.numerator().degree(), 1);
  EXPECT_EQ(pair.denominator().degree(), 2);
  EXPECT_EQ(pair.denominator().roots_at_zero(), 0);
  for (double f : {0.3, 4.0, 9.2, 23.5, 400.0}) {
    const Complex ideal = integrator().at_hz(f) * highpass2(4.0, 0.707).at_hz(f);
    EXPECT_NEAR(std::abs(pair.at_hz(f) - ideal), 0.0, 1e-15 * std::abs(ideal) + 1e-300);
  }
}

TEST(Polynomial, RootsAreExactConjugatesAndReal) {
  // (s + 1)(s + 2)(s^2 + 2 s + 5)
  const Polynomial p = Polynomial::from_roots({{-1, 0}, {-2, 0}, {-1, 2}, {-1, -2}}, 3.0);
  EXPECT_DOUBLE_EQ(p.leading(), 3.0);
  auto r = p.roots();
  ASSERT_EQ(r.size(), 4U);
  int real = 0, complex_pairs = 0;
  for (const auto& z : r) {
    EXPECT_LT(std::abs(p.evaluate(z)), 1e-10);
    if (z.imag() == 0.0) ++real;
    if (z.imag() > 0.0) {
      ++complex_pairs;
      EXPECT_NE(std::find(r.begin(), r.end(), std::conj(z)), r.end());
    }
  }
  EXPECT_EQ(real, 2);
  EXPECT_EQ(complex_pairs, 1);
  EXPECT_EQ(Polynomial({0.0, 0.0, 1.0, 2.0}).roots_at_zero(), 2);
}

TEST(Polynomial, DescendingRoundTripAndTrim) {
  const Polynomial p = Polynomial::from_descending({0.0, 2.0, 3.0, 4.0});
  EXPECT_EQ(p.degree(), 2);
  EXPECT_EQ(p.descending(), (std::vector<double>{2.0, 3.0, 4.0}));
  EXPECT_THROW((void)TransferFunction(Polynomial({1.0}), Polynomial({0.0})), std::invalid_argument);
}

}  // namespace
}  // namespace robodamp::filters
