// The DVF controller: polarity, 1/T, limits, gain ramp, parameter hand-over, rejected requests.
#include <gtest/gtest.h>

#include <cmath>

#include "control/controller.hpp"
#include "test_util.hpp"

namespace robodamp::control {
namespace {

// A pass-through chain, so each test sees exactly one mechanism of the output stage.
ControllerParams identity(double gain = 1.0) {
  ControllerParams p;
  p.fs_hz = 5000.0;
  p.sections.count = 1;  // b0 = 1
  p.sections_gain = 1.0;
  p.gain_ns_per_m = gain;
  p.gain_ramp_s = 0.0;
  p.polarity = 1;
  p.actuator_constant_n_per_v = 4.8;
  p.force_limit_n = 36.0;
  p.voltage_limit_v = 10.0;
  p.slew_rate_v_per_s = 1e9;
  return p;
}

TEST(Controller, ForceOverActuatorConstantIsTheCommand) {
  Controller c(identity(2.0));
  EXPECT_DOUBLE_EQ(c.update(3.0), 2.0 * 3.0 / 4.8);
  EXPECT_DOUBLE_EQ(c.force_command_n(), 6.0);
}

TEST(Controller, PolarityIsExplicit) {
  ControllerParams p = identity(2.0);
  Controller plus(p);
  p.polarity = -1;
  Controller minus(p);
  for (double x : {0.5, -1.25, 3.0}) EXPECT_DOUBLE_EQ(plus.update(x), -minus.update(x));
  // The default chain too: same filters, opposite command.
  auto d = test::design_preset("horizontal_c2");
  Controller a(d.params);
  d.params.polarity = -d.params.polarity;
  Controller b(d.params);
  for (int i = 0; i < 1000; ++i) {
    const double x = std::sin(i * 0.0116);
    ASSERT_DOUBLE_EQ(a.update(x), -b.update(x));
  }
}

TEST(Controller, ForceLimitThenVoltageLimitAreCounted) {
  Controller c(identity(1.0));
  EXPECT_DOUBLE_EQ(c.update(100.0), 36.0 / 4.8);  // 100 N asked, 36 N allowed
  EXPECT_DOUBLE_EQ(c.force_command_n(), 36.0);
  EXPECT_DOUBLE_EQ(c.update(-100.0), -36.0 / 4.8);
  EXPECT_EQ(c.counters().force_limited, 2U);
  ControllerParams p = identity(1.0);
  p.actuator_constant_n_per_v = 1.0;  // 36 N would need 36 V
  Controller v(p);
  EXPECT_DOUBLE_EQ(v.update(20.0), 10.0);
  EXPECT_EQ(v.counters().voltage_limited, 1U);
  EXPECT_EQ(v.counters().force_limited, 0U);
}

TEST(Controller, SlewRateLimitsTheStep) {
  ControllerParams p = identity(4.8);
  p.slew_rate_v_per_s = 5000.0;  // 1 V per sample at 5 kHz
  Controller c(p);
  EXPECT_NEAR(c.update(5.0), 1.0, 1e-12);
  EXPECT_NEAR(c.update(5.0), 2.0, 1e-12);
  for (int i = 0; i < 3; ++i) (void)c.update(5.0);
  EXPECT_NEAR(c.update(5.0), 5.0, 1e-12);
  EXPECT_EQ(c.counters().slew_limited, 4U);
}

TEST(Controller, GainChangesRampInsteadOfStepping) {
  ControllerParams p = identity(1000.0);
  p.gain_ramp_s = 0.1;  // 500 samples
  p.force_limit_n = 1e9;
  p.voltage_limit_v = 1e9;
  Controller c(p);
  EXPECT_DOUBLE_EQ(c.update(0.01), 1000.0 * 0.01 / 4.8);
  ASSERT_EQ(c.set_gain(2000.0), RequestStatus::kAccepted);
  double prev = c.command_v();
  double max_step = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double v = c.update(0.01);
    max_step = std::max(max_step, std::abs(v - prev));
    prev = v;
  }
  EXPECT_NEAR(prev, 2000.0 * 0.01 / 4.8, 1e-9);
  EXPECT_NEAR(c.gain_ns_per_m(), 2000.0, 1e-9);
  EXPECT_NEAR(max_step, (1000.0 * 0.01 / 4.8) / 500.0, 1e-9);  // one ramp step, never the whole change
}

TEST(Controller, RequestsOutsideTheConfiguredRangeAreRefused) {
  Controller c(identity(10.0));
  EXPECT_EQ(c.set_gain(NAN), RequestStatus::kRejectedOutOfRange);
  EXPECT_EQ(c.set_gain(-1.0), RequestStatus::kRejectedOutOfRange);
  EXPECT_EQ(c.set_gain(kMaxGainNsPerM * 2), RequestStatus::kRejectedOutOfRange);
  ControllerParams other = identity(10.0);
  other.fs_hz = 10000.0;
  EXPECT_EQ(c.request_params(other), RequestStatus::kRejectedSampleRate);
  EXPECT_EQ(c.counters().rejected_requests, 4U);
  EXPECT_DOUBLE_EQ(c.update(1.0), 10.0 / 4.8);  // unchanged
}

TEST(Controller, NonFiniteSamplesAreCountedAndHoldTheCommand) {
  auto d = test::design_preset("horizontal_c2");
  Controller c(d.params);
  double last = 0.0;
  for (int i = 0; i < 5000; ++i) last = c.update(0.3 * std::sin(i * 0.0116));
  EXPECT_EQ(c.update(NAN), last);
  EXPECT_EQ(c.update(INFINITY), last);
  EXPECT_EQ(c.counters().nonfinite_inputs, 2U);
  for (int i = 0; i < 5000; ++i) ASSERT_TRUE(std::isfinite(c.update(0.3 * std::sin(i * 0.0116))));
}

TEST(Controller, ParameterHandOverFadesOutSwapsAndFadesIn) {
  // Horizontal C2 (polarity +1) -> horizontal C1 (polarity -1) while a 9.2 Hz vibration runs.
  const auto c2 = test::design_preset("horizontal_c2");
  const auto c1 = test::design_preset("horizontal_c1");
  Controller c(c2.params);
  const double fs = c2.params.fs_hz;
  auto accel = [&](int i) { return 0.05 * std::sin(robodamp::kTwoPi * 9.2 * i / fs); };
  std::vector<double> v;
  int i = 0;
  for (; i < 20000; ++i) v.push_back(c.update(accel(i)));
  double normal = 0.0;
  for (int k = 15001; k < 20000; ++k) normal = std::max(normal, std::abs(v[k] - v[k - 1]));
  ASSERT_EQ(c.request_params(c1.params), RequestStatus::kAccepted);
  EXPECT_TRUE(c.handover_pending());
  const int ramp = static_cast<int>(c2.params.gain_ramp_s * fs);
  const int settle = static_cast<int>(std::ceil(c1.params.settle_s * fs));
  EXPECT_GT(c1.params.settle_s, 1.0);  // C1's double pole at 0.5 Hz
  for (; i < 20000 + settle + ramp + 10; ++i) v.push_back(c.update(accel(i)));
  EXPECT_FALSE(c.handover_pending());
  EXPECT_NEAR(v[20000 + settle - 2], 0.0, 1e-9);  // faded out before the swap
  EXPECT_NE(v[20000 + settle - ramp - 3], 0.0);   // and not earlier than needed
  double worst = 0.0;
  for (int k = 20000; k < i; ++k) worst = std::max(worst, std::abs(v[k] - v[k - 1]));
  // Compare with the larger of the two controllers' own sample-to-sample change on this vibration (a
  // swap of sections without the shadow warm-up gave about 10x; a jump would be ~100x: the command
  // amplitude is ~85 times its per-sample change at 9.2 Hz and 5 kHz).
  Controller c1_alone(c1.params);
  double normal_c1 = 0.0, prev = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double y = c1_alone.update(accel(k));
    if (k > 15000) normal_c1 = std::max(normal_c1, std::abs(y - prev));
    prev = y;
  }
  EXPECT_LT(worst, 1.2 * std::max(normal, normal_c1));
  EXPECT_EQ(c.params().polarity, -1);
  // After the hand-over it is the C1 controller, as if it had always run (filter history is the same input).
  Controller ref(c1.params);
  double got = 0.0, want = 0.0;
  for (int k = 0; k < i + 40000; ++k) {
    want = ref.update(accel(k));
    if (k >= i) got = c.update(accel(k));
  }
  EXPECT_NEAR(got, want, 1e-6 * std::abs(want) + 1e-9);
}

// A robot moving through narrow pose regions asks for the next set while the last hand-over is still fading
// in. The next swap must still wait for its own fade-out: swapping when the fade-in ended put the old
// output scale on the new chain (a set with a sections gain 230 times smaller drove the HIL to saturation).
TEST(Controller, AHandOverAskedDuringAFadeInStillFadesOutBeforeItsSwap) {
  ControllerParams a = identity(1.0), b = identity(1.0), c = identity(1.0);
  for (ControllerParams* p : {&a, &b, &c}) p->gain_ramp_s = 0.02, p->settle_s = 1.0;  // fade 100 samples, warm-up 4900
  b.sections_gain = 2.0;
  c.sections_gain = 1.0 / 230.0;  // the same K through a chain of another scale
  Controller ctl(a);
  ASSERT_EQ(ctl.request_params(b), RequestStatus::kAccepted);
  int i = 0;
  for (; ctl.handover_pending(); ++i) {
    ASSERT_LT(i, 10000) << "b never swapped in";
    (void)ctl.update(0.1);
  }
  for (int k = 0; k < 30; ++k, ++i) (void)ctl.update(0.1);  // 30 samples into b's fade-in
  ASSERT_FALSE(ctl.handover_pending());
  ASSERT_EQ(ctl.request_params(c), RequestStatus::kAccepted);
  double largest_gain = 0.0, at_swap = -1.0, before = 0.0;
  for (int k = 0; k < 6000; ++k) {
    const bool pending = ctl.handover_pending();
    const double y = ctl.update(0.1);
    largest_gain = std::max(largest_gain, std::abs(ctl.gain_ns_per_m()));
    if (pending && !ctl.handover_pending()) at_swap = std::abs(before);
    before = y;
  }
  EXPECT_FALSE(ctl.handover_pending());
  EXPECT_LE(largest_gain, 1.0 + 1e-9);  // K never above the sets' 1 N s/m
  EXPECT_GE(at_swap, 0.0);
  EXPECT_LE(at_swap, 0.0101 * 0.1 * 2.0 / 4.8);  // faded out before the swap: one ramp step (of 100) of b's output
  EXPECT_NEAR(ctl.gain_ns_per_m(), 1.0, 1e-9);
}

TEST(Controller, HandOverWithoutRampStillSwapsTheSections) {
  // Zero ramp, zero settling time: the new sections must still be in force when the new limits are.
  ControllerParams a = identity(1.0), b = identity(1.0);
  b.sections.sections[0].b0 = 3.0;
  Controller c(a);
  ASSERT_EQ(c.request_params(b), RequestStatus::kAccepted);
  for (int i = 0; i < 3; ++i) (void)c.update(1.0);
  EXPECT_FALSE(c.handover_pending());
  EXPECT_DOUBLE_EQ(c.update(1.0), 3.0 / 4.8);
}

TEST(Controller, ResetStartsFromSteadyStateWithoutSlewTransient) {
  auto d = test::design_preset("horizontal_c2");
  Controller c(d.params);
  c.reset(0.8);  // an offset at start-up
  for (int i = 0; i < 10000; ++i) ASSERT_NEAR(c.update(0.8), 0.0, 1e-9);
  EXPECT_EQ(c.counters().slew_limited, 0U);
}

// The spindle-locked notches in the controller: the tooth frequency from the speed and the configured
// teeth, the command at it cut by the depth, bad speeds refused, counted and parking the notches.
TEST(Controller, SpindleSpeedSteersTheHarmonicNotchesAndBadSpeedsParkThem) {
  ControllerParams p = identity(4.8);  // 1 V per m/s^2
  p.harmonic_notch.enabled = true;
  p.harmonic_notch.harmonics = 3;
  p.harmonic_notch.bandwidth_hz = 20.0;
  p.harmonic_notch.depth_db = 40.0;
  p.harmonic_notch.min_hz = 20.0;
  p.spindle_teeth = 3;
  p.spindle_rpm_max = 20000.0;
  Controller c(p);
  ASSERT_EQ(c.set_spindle_rpm(12000.0), RequestStatus::kAccepted);  // 600 Hz
  double in = 0.0, out = 0.0;
  for (int i = 0; i < 15000; ++i) {
    const double x = 0.1 * std::sin(2.0 * M_PI * 600.0 * i / 5000.0), y = c.update(x);
    if (i >= 10000) in += x * x, out += y * y;
  }
  EXPECT_NEAR(10.0 * std::log10(out / in), -40.0, 0.5);
  EXPECT_DOUBLE_EQ(c.notches().centre_hz(), 600.0);
  for (double bad : {std::nan(""), -1.0, 25000.0})
    EXPECT_EQ(c.set_spindle_rpm(bad), RequestStatus::kRejectedOutOfRange);
  EXPECT_EQ(c.counters().spindle_refused, 3U);
  for (int i = 0; i < 2000; ++i) (void)c.update(0.0);
  EXPECT_EQ(c.notches().fade(), 0.0);    // parked
  EXPECT_DOUBLE_EQ(c.update(0.5), 0.5);  // and out of the signal path
}

}  // namespace
}  // namespace robodamp::control
