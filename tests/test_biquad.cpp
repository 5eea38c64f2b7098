// The real-time cascade: sine in/settle, bounded offset response, NaN guard, reset and coefficient swap.
#include <gtest/gtest.h>

#include <cmath>

#include "filters/biquad.hpp"
#include "filters/design.hpp"
#include "filters/harmonic_notch.hpp"
#include "test_util.hpp"

namespace robodamp::filters {
namespace {

BiquadCascade default_chain(double fs = 5000.0) {
  return BiquadCascade(test::design_preset("horizontal_c2", fs).params.sections);
}

// Drives the cascade with a sine until it settles, then fits amplitude and phase over whole periods.
Complex measured_response(BiquadCascade c, double f, double fs, double settle_s) {
  const int settle = static_cast<int>(settle_s * fs);
  const int periods = 20;
  const int n = static_cast<int>(std::round(periods * fs / f));
  for (int i = 0; i < settle; ++i) (void)c.process(std::sin(kTwoPi * f * i / fs));
  double re = 0.0, im = 0.0;
  for (int i = settle; i < settle + n; ++i) {
    const double ph = kTwoPi * f * i / fs;
    const double y = c.process(std::sin(ph));
    re += y * std::sin(ph);
    im += y * std::cos(ph);
  }
  return Complex(2.0 * re / n, 2.0 * im / n);
}

TEST(BiquadCascade, SineInSettlesToTheDesignedGainAndPhase) {
  for (double fs : {1000.0, 5000.0}) {
    const auto d = test::design_preset("horizontal_c2", fs);
    for (double f : {5.0, 9.2, 21.0, 23.5, 80.0}) {
      const Complex want = d.filters_digital(f) / d.params.sections_gain;
      const Complex got = measured_response(BiquadCascade(d.params.sections), f, fs, 30.0);
      EXPECT_NEAR(magnitude_db(got), magnitude_db(want), 0.01) << f << " Hz at " << fs;
      EXPECT_NEAR(test::phase_diff_deg(phase_deg(got), phase_deg(want)), 0.0, 0.1) << f << " Hz at " << fs;
    }
  }
}

TEST(BiquadCascade, ConstantOffsetStaysBoundedOverTenMillionSamples) {
  // A constant accelerometer offset (here 1 m/s^2, far above an IEPE sensor's) must never wind up.
  BiquadCascade c = default_chain();
  double peak = 0.0, last = 0.0;
  for (int i = 0; i < 10'000'000; ++i) {
    last = c.process(1.0);
    peak = std::max(peak, std::abs(last));
  }
  EXPECT_TRUE(std::isfinite(peak));
  EXPECT_LT(peak, 1.0);
  EXPECT_LT(std::abs(last), 1e-12);  // and it decays: the chain blocks DC
}

TEST(BiquadCascade, LeakyIntegratorWithoutHighpassStaysBounded) {
  const DigitalDesign d = bilinear_sos(integrator(0.1), 5000.0, 9.2);
  BiquadCascade c(SosCoefficients::from(d.sections));
  double y = 0.0;
  for (int i = 0; i < 10'000'000; ++i) y = c.process(1.0);
  // Steady state of 1/(s + 2 pi 0.1) for a unit step, in the section's normalised scale.
  EXPECT_NEAR(y * d.gain, 1.0 / (kTwoPi * 0.1), 1e-6);
}

TEST(BiquadCascade, NonFiniteInputIsCountedAndNeverEntersTheState) {
  BiquadCascade c = default_chain();
  BiquadCascade reference = default_chain();
  for (int i = 0; i < 20000; ++i) {
    const double x = std::sin(kTwoPi * 9.2 * i / 5000.0);
    (void)reference.process(x);
    const double y = c.process(x);
    if (i == 10000) {
      const double held = c.last_output();
      EXPECT_EQ(c.process(NAN), held);
      EXPECT_EQ(c.process(INFINITY), held);
      EXPECT_EQ(c.process(-INFINITY), held);
    }
    ASSERT_TRUE(std::isfinite(y));
  }
  EXPECT_EQ(c.nonfinite_input_count(), 3U);
  EXPECT_EQ(c.state_reset_count(), 0U);
  // Skipped samples do not disturb the state: the filter continues exactly as the reference.
  for (int i = 20000; i < 20100; ++i) {
    const double x = std::sin(kTwoPi * 9.2 * i / 5000.0);
    EXPECT_DOUBLE_EQ(c.process(x), reference.process(x));
  }
}

TEST(BiquadCascade, OverflowClearsTheStateAndIsCounted) {
  // A gain section and a huge (finite) input: the product overflows to infinity.
  SosCoefficients k = default_chain().coefficients();
  k.sections[0].b0 = 1e10;
  BiquadCascade c(k);
  const double y = c.process(1e300);
  EXPECT_EQ(y, 0.0);
  EXPECT_GE(c.state_reset_count(), 1U);
  for (int i = 0; i < 1000; ++i) EXPECT_TRUE(std::isfinite(c.process(0.1)));
}

TEST(BiquadCascade, ResetToSteadyStateGivesNoGlitch) {
  const DigitalDesign lp = bilinear_sos(lowpass2(50.0, 0.707) * lowpass2(50.0, 0.707), 5000.0, 50.0);
  BiquadCascade c(SosCoefficients::from(lp.sections));
  for (int i = 0; i < 1000; ++i) (void)c.process(std::sin(i * 0.01) * 3.0);
  c.reset(2.0);
  const double dc = digital_response(lp.sections, 1.0, 0.0, 5000.0).real();
  for (int i = 0; i < 5000; ++i) ASSERT_NEAR(c.process(2.0), 2.0 * dc, 1e-12) << i;
  // The default chain blocks DC: after reset on an offset the output is zero from the first sample.
  BiquadCascade chain = default_chain();
  chain.reset(0.37);
  for (int i = 0; i < 5000; ++i) ASSERT_NEAR(chain.process(0.37), 0.0, 1e-12);
}

// Largest sample-to-sample change of the output over a window.
double max_step(const std::vector<double>& y, std::size_t from, std::size_t to) {
  double m = 0.0;
  for (std::size_t i = from + 1; i < to; ++i) m = std::max(m, std::abs(y[i] - y[i - 1]));
  return m;
}

TEST(BiquadCascade, CoefficientSwapAtASampleBoundaryDoesNotJump) {
  const double fs = 5000.0;
  // Retune the 3 Hz notch to 6 Hz and the low-pass from 50 to 12 Hz while a 9.2 Hz vibration runs.
  auto design = [&](double notch_hz, double lp_hz) {
    std::vector<BiquadCoefficients> s;
    for (const auto& tf : {lowpass2(lp_hz, 0.707), notch(notch_hz, 4.0)}) {
      const DigitalDesign d = bilinear_sos(tf, fs, lp_hz);
      s.insert(s.end(), d.sections.begin(), d.sections.end());
    }
    return SosCoefficients::from(s);
  };
  const SosCoefficients a = design(3.0, 50.0), b = design(6.0, 12.0);
  const std::size_t n = 40000, swap_at = 30000;
  // An offset (gravity on a tilted sensor) plus the vibration.
  auto input = [&](std::size_t i) { return 2.0 + std::sin(kTwoPi * 9.2 * static_cast<double>(i) / fs); };
  BiquadCascade c(a);
  std::vector<double> y;
  for (std::size_t i = 0; i < n; ++i) {
    if (i == swap_at - 2) c.request_swap(b);  // in force from sample swap_at
    y.push_back(c.process(input(i)));
  }
  // The same swap done naively (new coefficients over the old TDF-II state) does jump: this is what
  // the history-preserving swap is for.
  struct S {
    double s1 = 0, s2 = 0;
  };
  std::vector<S> st(a.count);
  std::vector<double> naive;
  for (std::size_t i = 0; i < n; ++i) {
    const SosCoefficients& k = i < swap_at ? a : b;
    double v = input(i);
    for (std::size_t j = 0; j < k.count; ++j) {
      const auto& q = k.sections[j];
      const double out = q.b0 * v + st[j].s1;
      st[j].s1 = q.b1 * v - q.a1 * out + st[j].s2;
      st[j].s2 = q.b2 * v - q.a2 * out;
      v = out;
    }
    naive.push_back(v);
  }
  const double normal = max_step(y, swap_at - 5000, swap_at);
  EXPECT_LE(max_step(y, swap_at - 1, swap_at + 500), 1.05 * normal);
  EXPECT_GT(max_step(naive, swap_at - 1, swap_at + 500), 2.0 * normal);
  // And the new coefficients are really in force: it settles to the new filter's response.
  BiquadCascade settled(b);
  std::vector<double> ref;
  for (std::size_t i = 0; i < n; ++i) ref.push_back(settled.process(input(i)));
  EXPECT_NEAR(y[n - 1], ref[n - 1], 1e-6 * normal);
}

TEST(BiquadCascade, SwapToTheSameCoefficientsChangesNothing) {
  BiquadCascade a = default_chain(), b = default_chain();
  const SosCoefficients same = a.coefficients();
  for (int i = 0; i < 10000; ++i) {
    const double x = std::sin(i * 0.013) + 0.2 * std::sin(i * 0.41);
    if (i == 5000) b.request_swap(same);
    const double ya = a.process(x), yb = b.process(x);
    ASSERT_NEAR(ya, yb, 1e-12) << i;  // rounding of the re-derived state, relative to the unit input
  }
}

TEST(BiquadCascade, SwapToADifferentSectionCount) {
  BiquadCascade c = default_chain();
  const SosCoefficients shorter = SosCoefficients::from(bilinear_sos(lowpass2(50.0, 0.707), 5000.0, 50.0).sections);
  for (int i = 0; i < 20000; ++i) (void)c.process(std::sin(i * 0.0116));
  c.request_swap(shorter);
  EXPECT_TRUE(c.swap_pending());
  (void)c.process(0.0);
  EXPECT_EQ(c.coefficients().count, 6U);
  (void)c.process(0.0);
  EXPECT_FALSE(c.swap_pending());
  EXPECT_EQ(c.coefficients().count, 1U);
  for (int i = 0; i < 20000; ++i) ASSERT_TRUE(std::isfinite(c.process(std::sin(i * 0.0116))));
  c.request_swap(default_chain().coefficients());
  for (int i = 0; i < 20000; ++i) ASSERT_TRUE(std::isfinite(c.process(std::sin(i * 0.0116))));
}

TEST(SosCoefficients, RejectsMoreThanTheFixedCapacity) {
  EXPECT_THROW((void)SosCoefficients::from(std::vector<BiquadCoefficients>(kMaxSections + 1)), std::length_error);
}

// --- Spindle-locked harmonic notches ---

HarmonicNotchSettings notch_settings() {
  HarmonicNotchSettings s;
  s.enabled = true;
  s.harmonics = 4;
  s.bandwidth_hz = 20.0;
  s.depth_db = 30.0;
  s.slew_fraction = 0.02;
  s.min_hz = 20.0;
  s.fade_s = 0.2;
  s.update_hz = 100.0;
  return s;
}

// Steady-state amplitude gain of the bank for a sine at f (RMS over the last second of three).
double bank_gain_db(HarmonicNotchBank bank, double f_hz, double fs) {
  double in = 0.0, out = 0.0;
  const int n = static_cast<int>(3 * fs);
  for (int i = 0; i < n; ++i) {
    const double x = std::sin(2.0 * M_PI * f_hz * i / fs), y = bank.process(x);
    if (i >= n - static_cast<int>(fs)) in += x * x, out += y * y;
  }
  return 10.0 * std::log10(out / in);
}

TEST(HarmonicNotch, AttenuatesEachEnabledHarmonicByTheConfiguredDepth) {
  const double fs = 5000.0, tooth_hz = 12000.0 * 3 / 60.0;  // 600 Hz
  HarmonicNotchBank bank(notch_settings(), fs);
  bank.set_tooth_frequency(tooth_hz);
  for (int i = 0; i < 5000; ++i) (void)bank.process(0.0);  // settle the fade
  ASSERT_DOUBLE_EQ(bank.fade(), 1.0);
  for (int k = 1; k <= 3; ++k) {
    const double g = bank_gain_db(bank, k * tooth_hz, fs);
    std::printf("harmonic %d (%.0f Hz): %.3f dB\n", k, k * tooth_hz, g);
    EXPECT_NEAR(g, -30.0, 0.5) << k;
    EXPECT_NEAR(20.0 * std::log10(std::abs(bank.response(k * tooth_hz))), -30.0, 0.5) << k;
  }
  // The 4th harmonic (2400 Hz) is at or above 0.45 fs = 2250 Hz: off.
  EXPECT_FALSE(bank.harmonic_on(3));
  EXPECT_NEAR(bank_gain_db(bank, 4 * tooth_hz, fs), 0.0, 0.1);
  // Far from every notch (the 9.2 Hz robot mode) the bank passes the signal.
  EXPECT_NEAR(std::abs(bank.response(9.2)), 1.0, 1e-3);
  std::printf("phase at 9.2 Hz: %.4f deg\n", std::arg(bank.response(9.2)) * 180.0 / M_PI);
}

// A sine at the robot mode plus one near the notches; the centre ramps 200 -> 320 Hz at the slew limit.
// The largest sample-to-sample output change stays within that of the same signal with the bank standing
// at either end (a coefficient change with the state kept adds no step of its own).
TEST(HarmonicNotch, MovingAtTheSlewLimitMakesNoLargerOutputStepThanStandingStill) {
  const double fs = 5000.0;
  auto run = [&](double from_hz, double to_hz, HarmonicNotchCounters* counters) {
    HarmonicNotchBank bank(notch_settings(), fs);
    bank.set_tooth_frequency(from_hz);
    double max_step = 0.0, last = 0.0;
    for (int i = 0; i < static_cast<int>(6 * fs); ++i) {
      if (i == static_cast<int>(1 * fs)) bank.set_tooth_frequency(to_hz);
      const double t = i / fs;
      const double x = std::sin(2.0 * M_PI * 9.2 * t) + 0.3 * std::sin(2.0 * M_PI * 150.0 * t);
      const double y = bank.process(x);
      if (i > static_cast<int>(0.5 * fs)) max_step = std::max(max_step, std::abs(y - last));
      last = y;
    }
    if (counters != nullptr) *counters = bank.counters();
    EXPECT_DOUBLE_EQ(bank.centre_hz(), to_hz);
    return max_step;
  };
  HarmonicNotchCounters moved{};
  const double at_200 = run(200.0, 200.0, nullptr), at_320 = run(320.0, 320.0, nullptr);
  const double moving = run(200.0, 320.0, &moved);
  std::printf("largest output step: %.6f at 200 Hz, %.6f at 320 Hz, %.6f moving (%llu slew-limited updates)\n", at_200,
              at_320, moving, static_cast<unsigned long long>(moved.slew_limited));
  EXPECT_GT(moved.slew_limited, 10U);
  EXPECT_LE(moving, std::max(at_200, at_320) * 1.001);
}

TEST(HarmonicNotch, ParksOnAStoppedOrUnknownSpindleAndPassesTheSignalExactly) {
  const double fs = 5000.0;
  HarmonicNotchBank bank(notch_settings(), fs);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(bank.process(0.25 * i), 0.25 * i);  // never started: faded out
  bank.set_tooth_frequency(400.0);
  for (int i = 0; i < 2000; ++i) (void)bank.process(0.0);
  EXPECT_DOUBLE_EQ(bank.fade(), 1.0);
  for (double bad : {std::nan(""), -100.0, HUGE_VAL}) bank.set_tooth_frequency(bad);
  EXPECT_EQ(bank.counters().invalid_inputs, 3U);
  EXPECT_EQ(bank.target_hz(), 0.0);
  // Faded out within fade_s (plus one update), then the input passes bit for bit.
  for (int i = 0; i < static_cast<int>(0.21 * fs) + 50; ++i) (void)bank.process(std::sin(0.01 * i));
  EXPECT_EQ(bank.fade(), 0.0);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(bank.process(0.5 * i), 0.5 * i);
  EXPECT_GT(bank.counters().parked, 0U);
  bank.set_tooth_frequency(5.0);  // below min_hz: still parked
  for (int i = 0; i < 500; ++i) (void)bank.process(0.0);
  EXPECT_EQ(bank.fade(), 0.0);
}

}  // namespace
}  // namespace robodamp::filters
