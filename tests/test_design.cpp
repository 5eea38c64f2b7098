// Digital realisation against the analog blocks: bilinear with pre-warping, factoring, pairing, rejection.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "filters/design.hpp"
#include "test_util.hpp"

namespace robodamp::filters {
namespace {

using test::phase_diff_deg;

struct NamedBlock {
  const char* name;
  TransferFunction tf;
  double prewarp_hz;
};

std::vector<NamedBlock> all_blocks() {
  return {{"lowpass2 50 Hz", lowpass2(50.0, 0.707), 50.0},
          {"integrator*highpass2 4 Hz", integrator() * highpass2(4.0, 0.707), 4.0},
          {"highpass2 4 Hz", highpass2(4.0, 0.707), 4.0},
          {"notch 3 Hz a 4 Hz", notch(3.0, 4.0), 3.0},
          {"C1 horizontal", compensator_c1(9.0, 0.15), 9.2},
          {"C1 vertical", compensator_c1(14.0, 0.15), 9.2},
          {"C2", compensator_c2(), 9.2},
          {"C3", compensator_c3(), 9.2},
          {"leaky integrator", integrator(0.1), 9.2}};
}

double analog_peak_db(const TransferFunction& tf, double fs) {
  double peak = -1e300;
  for (int i = 0; i <= 4000; ++i) peak = std::max(peak, magnitude_db(tf.at_hz(0.01 * std::pow(50.0 * fs, i / 4000.0))));
  return peak;
}

// Issue acceptance: digital vs analog within 0.1 dB and 0.5 deg from 1 Hz to fs/20 wherever the
// block's gain is within 20 dB of its maximum, at 1, 5 and 10 kHz, with plain pre-warped bilinear.
TEST(BilinearDesign, DigitalMatchesAnalogOverTheBand) {
  for (double fs : {1000.0, 5000.0, 10000.0}) {
    for (const auto& b : all_blocks()) {
      SCOPED_TRACE(std::string(b.name) + " at fs = " + std::to_string(fs));
      const DigitalDesign d = bilinear_sos(b.tf, fs, b.prewarp_hz);
      const double peak_db = analog_peak_db(b.tf, fs);
      int checked = 0;
      double worst_db = 0.0, worst_deg = 0.0;
      for (int i = 0; i <= 500; ++i) {
        const double f = std::pow(fs / 20.0, i / 500.0);  // 1 Hz .. fs/20
        const Complex ha = b.tf.at_hz(f);
        if (magnitude_db(ha) < peak_db - 20.0) continue;
        const Complex hd = digital_response(d.sections, d.gain, f, fs);
        worst_db = std::max(worst_db, std::abs(magnitude_db(hd) - magnitude_db(ha)));
        worst_deg = std::max(worst_deg, std::abs(phase_diff_deg(phase_deg(hd), phase_deg(ha))));
        ++checked;
      }
      EXPECT_GT(checked, 0);  // e.g. C1 (50 dB at DC) and the leaky integrator qualify only near 1 Hz
      EXPECT_LT(worst_db, 0.1);
      EXPECT_LT(worst_deg, 0.5);
    }
  }
}

TEST(BilinearDesign, ExactAtThePrewarpFrequency) {
  for (double fs : {1000.0, 5000.0, 20000.0})
    for (const auto& b : all_blocks()) {
      const DigitalDesign d = bilinear_sos(b.tf, fs, b.prewarp_hz);
      const Complex ha = b.tf.at_hz(b.prewarp_hz), hd = digital_response(d.sections, d.gain, b.prewarp_hz, fs);
      EXPECT_LT(std::abs(hd - ha), 1e-9 * std::max(std::abs(ha), 1.0)) << b.name << " fs " << fs;
    }
}

TEST(BilinearDesign, SectionsEqualTheBilinearImageEverywhere) {
  // Factoring and pairing must not change the response: compare with tf at the warped frequency.
  for (const auto& b : all_blocks()) {
    const DigitalDesign d = bilinear_sos(b.tf, 5000.0, b.prewarp_hz);
    for (double f : {0.2, 1.0, 9.2, 100.0, 1000.0, 2400.0}) {
      const Complex ref = bilinear_response(b.tf, f, 5000.0, b.prewarp_hz);
      EXPECT_LT(std::abs(digital_response(d.sections, d.gain, f, 5000.0) - ref), 1e-9 * std::abs(ref) + 1e-13)
          << b.name << " at " << f << " Hz";
    }
  }
}

TEST(BilinearDesign, SectionsAreNormalisedAndStrictlyStable) {
  for (const auto& b : all_blocks()) {
    const DigitalDesign d = bilinear_sos(b.tf, 5000.0, b.prewarp_hz);
    for (const auto& s : d.sections) {
      double peak = 0.0;
      for (int i = 0; i <= 2000; ++i)
        peak = std::max(peak, std::abs(digital_response({s}, 1.0, 2500.0 * i / 2000.0, 5000.0)));
      EXPECT_LT(peak, 1.0 + 1e-3) << b.name;
      EXPECT_LT(pole_radius(s), 1.0) << b.name;
    }
  }
}

TEST(BilinearDesign, PoleRadiusOfRealAndComplexPairs) {
  // (1 - 0.5 z^-1)(1 + 0.9 z^-1) and a pair at radius 0.8.
  EXPECT_NEAR(pole_radius({1, 0, 0, 0.4, -0.45}), 0.9, 1e-12);
  EXPECT_NEAR(pole_radius({1, 0, 0, -2 * 0.8 * std::cos(0.3), 0.64}), 0.8, 1e-12);
}

TEST(BilinearDesign, HigherOrderCompensatorIsFactoredIntoSections) {
  // A 7th-order rational compensator given only by its expanded coefficients: real and complex
  // poles at very different frequencies, one zero at s = 0, one non-minimum-phase zero.
  const std::vector<Complex> poles = {{-20, 0}, {-3000, 0}, {-40, 150}, {-40, -150}, {-5, 60}, {-5, -60}, {-700, 0}};
  const std::vector<Complex> zeros = {{0, 0}, {-100, 0}, {30, 0}, {-2, 80}, {-2, -80}};
  const TransferFunction tf(Polynomial::from_roots(zeros, 17.0), Polynomial::from_roots(poles, 1.0));
  const DigitalDesign d = bilinear_sos(tf, 5000.0, 9.2);
  EXPECT_EQ(d.sections.size(), 4U);
  for (double f = 1.0; f < 250.0; f *= 1.1) {
    const Complex ha = tf.at_hz(f), hd = digital_response(d.sections, d.gain, f, 5000.0);
    EXPECT_NEAR(magnitude_db(hd), magnitude_db(ha), 0.1) << f;
    EXPECT_NEAR(phase_diff_deg(phase_deg(hd), phase_deg(ha)), 0.0, 0.5) << f;
  }
  // The lightly damped pair (radius closest to 1) is realised last.
  const auto& last = d.sections.back();
  EXPECT_NEAR(std::sqrt(last.a2), std::abs(std::exp(Complex(-5, 60) / 5000.0)), 1e-4);
}

TEST(BilinearDesign, ImpulseResponsesDecay) {
  for (const auto& b : all_blocks()) {
    const DigitalDesign d = bilinear_sos(b.tf, 5000.0, b.prewarp_hz);
    BiquadCascade c(SosCoefficients::from(d.sections));
    double early = 0.0, late = 0.0;
    const int n = 5000 * 60;  // 60 s: the slowest pole is the 0.1 Hz leak, tau = 1.6 s
    for (int i = 0; i < n; ++i) {
      const double y = c.process(i == 0 ? 1.0 : 0.0);
      (i < n / 2 ? early : late) += y * y;
    }
    EXPECT_GT(early, 0.0) << b.name;
    EXPECT_LT(late, 1e-12 * early) << b.name;
  }
}

TEST(BilinearDesign, RejectsWhatCannotRun) {
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const DesignError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Pure integrator: pole at s = 0 (marginally stable).
  EXPECT_NE(message([] { (void)bilinear_sos(integrator(), 5000.0, 9.2); }).find("marginally stable"),
            std::string::npos);
  // Unstable pole.
  const TransferFunction unstable(Polynomial({1.0}), Polynomial({-3.0, 1.0}));
  EXPECT_NE(message([&] { (void)bilinear_sos(unstable, 5000.0, 9.2); }).find("pole at s = 3"), std::string::npos);
  // Non-finite coefficient.
  const TransferFunction nan_tf(Polynomial({NAN, 1.0}), Polynomial({1.0, 1.0}));
  EXPECT_NE(message([&] { (void)bilinear_sos(nan_tf, 5000.0, 9.2); }).find("non-finite"), std::string::npos);
  // Improper (a differentiator).
  const TransferFunction improper(Polynomial({0.0, 0.0, 1.0}), Polynomial({1.0, 1.0}));
  EXPECT_NE(message([&] { (void)bilinear_sos(improper, 5000.0, 9.2); }).find("improper"), std::string::npos);
  // Cut-off at or above Nyquist.
  EXPECT_NE(message([] { (void)bilinear_sos(lowpass2(2500.0, 0.7), 5000.0, 2500.0); }).find("Nyquist"),
            std::string::npos);
  EXPECT_NE(message([] { (void)bilinear_sos(lowpass2(3000.0, 0.7), 5000.0, 3000.0); }).find("Nyquist"),
            std::string::npos);
  EXPECT_THROW((void)bilinear_sos(lowpass2(50.0, 0.7), 0.0, 50.0), DesignError);
  EXPECT_THROW((void)bilinear_sos(lowpass2(50.0, 0.7), 5000.0, NAN), DesignError);
}

// The published phases at 9.2 Hz, from the digital blocks as the default chain realises them.
TEST(ChainDesign, PublishedPhasesFromTheDigitalBlocks) {
  for (double fs : {1000.0, 5000.0, 10000.0}) {
    SCOPED_TRACE(fs);
    auto phase_of = [&](const analysis::ChainDesign& d, const std::string& name) {
      for (std::size_t i = 0; i < d.blocks.size(); ++i)
        if (d.blocks[i].name == name) return phase_deg(d.block_digital(i, 9.2));
      ADD_FAILURE() << "no block " << name;
      return 0.0;
    };
    const auto c2 = test::design_preset("horizontal_c2", fs);
    EXPECT_NEAR(phase_of(c2, "compensator"), 34.3, 0.1);
    EXPECT_NEAR(phase_of(c2, "highpass2"), 37.0, 0.5);
    EXPECT_NEAR(phase_of(c2, "notch"), 26.0, 0.5);
    EXPECT_NEAR(phase_of(c2, "lowpass2") + phase_of(c2, "lowpass2_2"), -30.1, 0.3);
    EXPECT_NEAR(phase_of(c2, "integrator"), -90.0, 0.1);
    EXPECT_NEAR(phase_of(test::design_preset("horizontal_c1", fs), "compensator"), -75.44, 0.05);
    EXPECT_NEAR(phase_of(test::design_preset("horizontal_c3", fs), "compensator"), 48.0, 0.1);
  }
}

// The integrator is realised with the high-pass: no marginally stable state, and no cost against the
// ideal 1/s chain at the robot modes (requirement: < 0.1 dB / 1 deg).
TEST(ChainDesign, IntegratorRealisationCostsNothingAtTheRobotModes) {
  for (const char* p : {"horizontal_c1", "horizontal_c2", "horizontal_c3", "vertical_c1"})
    for (double fs : {1000.0, 5000.0, 10000.0, 20000.0}) {
      const auto d = test::design_preset(p, fs);
      for (double f : {9.2, 21.0, 23.5}) {
        const Complex ideal = d.filters_analog(f);  // contains the exact 1/s
        const Complex real = d.filters_digital(f);
        EXPECT_LT(std::abs(magnitude_db(real) - magnitude_db(ideal)), 0.1) << p << " " << fs << " " << f;
        EXPECT_LT(std::abs(phase_diff_deg(phase_deg(real), phase_deg(ideal))), 1.0) << p << " " << fs << " " << f;
      }
      for (std::size_t i = 0; i < d.params.sections.count; ++i) {
        const auto& s = d.params.sections.sections[i];
        EXPECT_GT(std::abs(1.0 + s.a1 + s.a2), 1e-12) << "pole at z = 1 in section " << i;
      }
    }
}

}  // namespace
}  // namespace robodamp::filters
