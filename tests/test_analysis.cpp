// The loop analysis: the corrected closed-loop equations, discrete stability by poles and by Nyquist,
// the gain limit and margins, the polarity, and the H1 estimator.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <thread>

#include "modal/receptance.hpp"
#include "analysis/gain_path.hpp"
#include "analysis/impact_command.hpp"
#include "analysis/loop_model.hpp"
#include "analysis/notch_speed_map.hpp"
#include "analysis/quiet_command.hpp"
#include "analysis/resolvent.hpp"
#include "analysis/chain_design.hpp"
#include "control/controller.hpp"
#include "filters/harmonic_notch.hpp"
#include "analysis/spectral.hpp"
#include "test_util.hpp"

namespace {

using namespace robodamp;
using analysis::Complex;

analysis::LoopModel model(const std::string& name) {
  return analysis::LoopModel(config::load_config_file(test::preset(name)));
}

TEST(LoopModel, ClosedLoopFollowsTheCorrectedEquations) {
  // docs/physics.md §1 (Eq. 10-12, H11 corrected), with every FRF in one consistent frame, the
  // physical one: L = G H22 / T, H22_cl = H22 / (1 + L), H11_cl = [H11 (1 + L) - H12 H21 G / T] / (1 + L).
  // In the table's frame H22 changes sign but H12 H21 does not: written with the table's H22 in L (as the
  // reference puts it, "sign per polarity"), the coupling term's sign must flip with it.
  const auto m = model("horizontal_c2");
  const auto& cfg = m.config();
  const double k = cfg.controller.gain_ns_per_m;
  for (double f : {5.0, 9.2, 14.0, 21.0, 23.5, 40.0}) {
    const Complex h11 = modal::frf_receptance(cfg.robot.frfs[0], f);
    const Complex h21 = -modal::frf_receptance(cfg.robot.frfs[1], f);  // physical: location 2 axis reversed
    const Complex h22 = -modal::frf_receptance(cfg.robot.frfs[2], f);
    const Complex h12 = h21;  // reciprocity
    // G / T: force per displacement fed back with negative sign (F_act = -G/T x2).
    const Complex g_over_t = -m.feedback_continuous(f, k, 1);
    const Complex l = g_over_t * h22;
    EXPECT_NEAR(std::abs(m.loop_continuous(f, k, 1) - l), 0.0, 1e-12 * std::abs(l)) << f;
    const Complex h22_cl = h22 / (1.0 + l), h11_cl = (h11 * (1.0 + l) - h12 * h21 * g_over_t) / (1.0 + l);
    EXPECT_NEAR(std::abs(m.closed_continuous(1, 1, f, k, 1) - h22_cl), 0.0, 1e-9 * std::abs(h22_cl)) << f;
    EXPECT_NEAR(std::abs(m.closed_continuous(0, 0, f, k, 1) - h11_cl), 0.0, 1e-9 * std::abs(h11_cl)) << f;
    // Table frame: L_table = G' H22_table / T with G' = -G; the coupling term then enters with +.
    const Complex h21_t = -h21, h22_t = -h22, g_t = -g_over_t, l_t = g_t * h22_t;
    EXPECT_NEAR(std::abs((h11 * (1.0 + l_t) + h21_t * h21_t * g_t) / (1.0 + l_t) - h11_cl), 0.0,
                1e-9 * std::abs(h11_cl));
  }
}

TEST(LoopModel, DiscreteLoopApproachesTheContinuousOneAtLowFrequency) {
  // The discrete loop adds only ZOH and one sample of computation delay (0.3 ms) to the continuous
  // model: within 1 % in magnitude and the phase of 1.5 samples at 9.2 Hz.
  const auto m = model("horizontal_c2");
  const double f = 9.2, k = 2000.0;
  const Complex lc = m.loop_continuous(f, k, 1), ld = m.loop_discrete(f, k, 1);
  EXPECT_NEAR(std::abs(ld) / std::abs(lc), 1.0, 0.01);
  const double extra_deg = std::arg(ld / lc) * 180.0 / M_PI;
  EXPECT_NEAR(extra_deg, -360.0 * f * 1.5 / 5000.0, 0.3);
}

TEST(LoopModel, PolesAndNyquistAgreeAcrossTheGainLimit) {
  for (const char* name : {"horizontal_c2", "horizontal_c1", "horizontal_c3"}) {
    const auto m = model(name);
    const int pol = m.config().controller.polarity;
    const auto k_max = analysis::max_stable_gain(m, pol);
    ASSERT_TRUE(k_max) << name;
    EXPECT_TRUE(m.stable(0.999 * *k_max, pol)) << name;
    EXPECT_FALSE(m.stable(1.001 * *k_max, pol)) << name;
    for (double factor : {0.3, 0.9, 0.99, 1.01, 1.2, 3.0}) {
      const double k = factor * *k_max;
      EXPECT_EQ(m.nyquist_encirclements(k, pol) == 0, m.stable(k, pol)) << name << " K = " << k;
    }
  }
}

// The controller-Hessenberg path (one reduction, then the QR iterations per gain) gives the dense solve's
// spectral radius: on the presets' loops at both polarities, and on random one-input systems of our own.
TEST(GainPath, SpectralRadiusIsTheDenseEigenvaluesAtEveryGain) {
  for (const char* name : {"horizontal_c2", "vertical_c1", "tuned_vertical"}) {
    const auto m = model(name);
    const analysis::GainPath path(m.open_loop_unit());
    for (int pol : {1, -1})
      for (double k : {0.0, 10.0, 300.0, 2000.0, 9000.0, 60000.0})
        EXPECT_NEAR(path.spectral_radius(k, pol), m.spectral_radius(k, pol), 1e-11 * m.spectral_radius(k, pol) + 1e-14)
            << name << " K " << k << " polarity " << pol;
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 3 + trial * 2;
    analysis::DiscreteSs s;
    s.a = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return g(rng); }) / std::sqrt(static_cast<double>(n));
    s.b = Eigen::MatrixXd::NullaryExpr(n, 1, [&] { return g(rng); });
    s.c = Eigen::MatrixXd::NullaryExpr(1, n, [&] { return g(rng); });
    const analysis::GainPath path(s);
    for (double k : {0.0, 0.01, 0.3, 2.0}) {
      const Eigen::MatrixXd closed = s.a - k * s.b * s.c;
      const double dense = Eigen::EigenSolver<Eigen::MatrixXd>(closed, false).eigenvalues().cwiseAbs().maxCoeff();
      EXPECT_NEAR(path.spectral_radius(k, -1), dense, 1e-10 * dense) << "n " << n << " K " << k;
    }
  }
}

TEST(LoopModel, GainMarginFromBisectionMatchesThePhaseCrossover) {
  const auto m = model("horizontal_c2");
  const auto r = analysis::analyse(m);
  ASSERT_TRUE(r.margins.gain_margin_db && r.margins.phase_crossover_hz);
  const double l = std::abs(m.loop_discrete(*r.margins.phase_crossover_hz, r.gain_ns_per_m, r.polarity));
  EXPECT_NEAR(-20.0 * std::log10(l), *r.margins.gain_margin_db, 0.05);
  ASSERT_TRUE(r.margins.delay_margin_ms && r.margins.phase_margin_deg);
  EXPECT_GT(*r.margins.phase_margin_deg, 0.0);
}

TEST(LoopModel, PolarityIsSettledByTheAnalysis) {
  // With the table's reversed location-2 axis no single polarity damps with both C1 and C2.
  const auto c2 = analysis::analyse(model("horizontal_c2"));
  const auto c1 = analysis::analyse(model("horizontal_c1"));
  EXPECT_EQ(c2.recommended_polarity, 1);
  EXPECT_EQ(c1.recommended_polarity, -1);
  EXPECT_EQ(analysis::analyse(model("vertical_c1")).recommended_polarity, -1);
  EXPECT_TRUE(c2.stable && c1.stable);
  EXPECT_TRUE(c2.modes.front().damps);
  // The wrong polarity amplifies the dominant mode: stable only at low gain, and no improvement.
  const auto m = model("horizontal_c2");
  const auto wrong = analysis::analyse(m, 2000.0, -1);
  EXPECT_FALSE(wrong.modes.front().damps);
  EXPECT_NE(wrong.notes.front().find("does not damp"), std::string::npos);
  if (wrong.stable) {
    for (const auto& f : wrong.frfs_discrete) EXPECT_LT(f.improvement_pct, 0.0) << f.name;
  }
}

TEST(LoopModel, UnstableConfigurationIsReportedAsSuch) {
  const auto m = model("horizontal_c2");
  const auto k_max = analysis::max_stable_gain(m, 1);
  const auto r = analysis::analyse(m, 1.5 * *k_max, 1);
  EXPECT_FALSE(r.stable);
  EXPECT_GT(r.spectral_radius, 1.0);
  EXPECT_GT(r.nyquist_encirclements, 0);
}

// The loop model's frequency responses through the diagonalised Phi against the LU of z I - Phi at every
// z, on each mounting's plant discretised at the loop rate; a defective Phi (a Jordan block) keeps the LU.
TEST(Resolvent, TheDiagonalFormIsTheLuSolveAndADefectivePhiKeepsTheLu) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const char* name : {"horizontal_c2", "vertical_c1"}) {
    const config::Config cfg = config::load_config_file(test::preset(name));
    const sim::PlantModel p = sim::build_plant_model(cfg);
    const sim::Zoh d = sim::discretise_zoh(p.ss.a, p.ss.b, 1.0 / cfg.loop.rate_hz);
    const analysis::Resolvent r(d.phi, d.gamma, p.ss.c);
    ASSERT_TRUE(r.diagonal()) << name;
    for (double f_hz = 0.5; f_hz < 0.5 * cfg.loop.rate_hz; f_hz *= 1.07) {
      const Complex z = std::exp(Complex(0.0, 2.0 * M_PI * f_hz / cfg.loop.rate_hz));
      Eigen::MatrixXcd m = -d.phi.cast<Complex>();
      m.diagonal().array() += z;
      const Eigen::MatrixXcd lu = p.ss.c.cast<Complex>() * m.partialPivLu().solve(d.gamma.cast<Complex>());
      EXPECT_LT((r(z) - lu).norm(), 1e-9 * lu.norm()) << name << " at " << f_hz << " Hz";
    }
  }
  Eigen::MatrixXd jordan{{0.9, 1.0, 0.0}, {0.0, 0.9, 1.0}, {0.0, 0.0, 0.9}}, b(3, 1), c(1, 3);
  b << u(rng), u(rng), u(rng);
  c << u(rng), u(rng), u(rng);
  const analysis::Resolvent r(jordan, b, c);
  EXPECT_FALSE(r.diagonal());
  const Complex z = std::exp(Complex(0.0, 0.3));
  const Eigen::Matrix3cd m = Complex(z) * Eigen::Matrix3cd::Identity() - jordan.cast<Complex>();
  EXPECT_LT(std::abs(r(z)(0, 0) - (c.cast<Complex>() * m.inverse() * b.cast<Complex>())(0, 0)), 1e-12);
}

TEST(Spectral, H1OfAKnownFilterWithAndWithoutOutputNoise) {
  // y = IIR(x) for white x; H1 recovers the filter, coherence 1 without noise; output noise leaves H1
  // unbiased and lowers the coherence.
  const double fs = 1000.0, a = 0.9;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> x(200000), y(x.size()), yn(x.size());
  double prev = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = n(rng);
    prev = x[i] + a * prev;  // 1 / (1 - a z^-1)
    y[i] = prev;
    yn[i] = prev + 2.0 * n(rng);
  }
  const auto e = analysis::welch_frf(x, y, fs, 1024, 0.5, 400.0);
  const auto en = analysis::welch_frf(x, yn, fs, 1024, 0.5, 400.0);
  for (std::size_t k = 5; k < e.f_hz.size(); k += 37) {
    const Complex h = 1.0 / (1.0 - a * std::exp(Complex(0.0, -2 * M_PI * e.f_hz[k] / fs)));
    EXPECT_NEAR(std::abs(e.h1[k] / h), 1.0, 0.02) << e.f_hz[k];
    EXPECT_GT(e.coherence[k], 0.995);
    EXPECT_NEAR(std::abs(en.h1[k] / h), 1.0, 0.15) << e.f_hz[k];
  }
  EXPECT_LT(en.coherence.back(), 0.9);
}

// The spindle-locked notches in the analysis: at 12 000 rpm x 3 teeth (600 Hz) three notches join the
// discrete loop and cost under 0.1 deg at the 9.2 Hz mode; at 600 rpm (30 Hz) four of them sit near the
// modes and cost 17 deg there, which the loop's K_max and margins then carry.
TEST(Analysis, HarmonicNotchesJoinTheLoopAtASpindleSpeed) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  config::HarmonicNotchConfig n;
  n.harmonics = 4, n.bandwidth_hz = 20.0, n.depth_db = 30.0;
  cfg.controller.harmonic_notch = n;
  cfg.spindle.teeth = 3;
  const analysis::LoopModel plain(cfg), fast(cfg, 12000.0), slow(cfg, 600.0), stopped(cfg, 0.0);
  EXPECT_EQ(plain.notch_count(), 0U);
  EXPECT_EQ(stopped.notch_count(), 0U);  // below min_hz: parked
  EXPECT_EQ(fast.notch_count(), 3U);     // the 4th harmonic, 2400 Hz, is above 0.45 fs
  EXPECT_EQ(slow.notch_count(), 4U);
  const double fast_deg = std::arg(fast.notch_response(9.2)) * 180.0 / M_PI;
  const double slow_deg = std::arg(slow.notch_response(9.2)) * 180.0 / M_PI;
  EXPECT_LT(std::abs(fast_deg), 0.1);
  EXPECT_LT(slow_deg, -10.0);
  // Three notches at 600 Hz change the 9.2 Hz loop by 0.03 deg: K_max within 0.5 %.
  const auto k_plain = analysis::max_stable_gain(plain, cfg.controller.polarity);
  const auto k_fast = analysis::max_stable_gain(fast, cfg.controller.polarity);
  ASSERT_TRUE(k_plain && k_fast);
  EXPECT_NEAR(*k_fast, *k_plain, 0.005 * *k_plain);
  // The notches' depth is in the discrete loop: its filter response at 600 Hz is 30 dB down.
  EXPECT_NEAR(20.0 * std::log10(std::abs(fast.chain_filters_digital(600.0) / plain.chain_filters_digital(600.0))),
              -30.0, 0.5);
}

// One rule of which notches are on: the loop analysis takes the designed controller's settings and the
// bank's rule, so at every steady speed (parked below min_hz, every harmonic, the top ones cut at
// 0.45 fs) the analysed notches are the ones the running bank has in its path, with its response.
TEST(Analysis, AnalysedNotchesAreTheRunningBanksAtEverySpeed) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  config::HarmonicNotchConfig n;
  n.harmonics = 6, n.bandwidth_hz = 15.0, n.depth_db = 25.0, n.min_hz = 12.0;
  cfg.controller.harmonic_notch = n;
  cfg.spindle.teeth = 2;
  const auto designed = analysis::design_chain(cfg).params.harmonic_notch;
  ASSERT_TRUE(designed.enabled);
  int saw_parked = 0, saw_cut = 0, saw_all = 0;
  for (const double rpm : {300.0, 359.0, 361.0, 3000.0, 20000.0, 33000.0, 44000.0, 67400.0, 90000.0}) {
    const double tooth_hz = rpm * cfg.spindle.teeth / 60.0;
    filters::HarmonicNotchBank bank(designed, cfg.loop.rate_hz);
    bank.set_tooth_frequency(tooth_hz);
    for (int i = 0; i < static_cast<int>(2.0 * cfg.loop.rate_hz); ++i) (void)bank.process(0.0);
    std::size_t running = 0;
    for (int k = 0; k < filters::kMaxHarmonics; ++k) running += bank.harmonic_gain(k) == 1.0;
    const analysis::LoopModel model(cfg, rpm);
    EXPECT_EQ(model.notch_count(), running) << rpm << " rpm";
    EXPECT_EQ(static_cast<int>(running),
              filters::HarmonicNotchBank::steady_count(designed, tooth_hz, cfg.loop.rate_hz));
    for (const double f : {9.2, tooth_hz, 1.5 * tooth_hz}) {
      const auto a = model.notch_response(f), b = bank.response(f);
      EXPECT_NEAR(std::abs(a - b), 0.0, 1e-9) << rpm << " rpm at " << f << " Hz";
    }
    saw_parked += running == 0;
    saw_all += running == 6;
    saw_cut += running > 0 && running < 6;
  }
  EXPECT_GT(saw_parked, 0);
  EXPECT_GT(saw_all, 0);
  EXPECT_GT(saw_cut, 0);
}

// The default preset with harmonic notches (harmonics, bandwidth, depth) on a spindle of `teeth` up to rpm_max.
struct NotchSettings {
  int harmonics;
  double bandwidth_hz, depth_db;
};
config::Config c2_with_notches(const NotchSettings& s, int teeth, double rpm_max) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  config::HarmonicNotchConfig n;
  n.harmonics = s.harmonics, n.bandwidth_hz = s.bandwidth_hz, n.depth_db = s.depth_db;
  cfg.controller.harmonic_notch = n;
  cfg.spindle.teeth = teeth;
  cfg.spindle.rpm_max = rpm_max;
  return cfg;
}

// A loop model is its sampled plant and its controller's side: the loop at a spindle speed made from the plain
// one (at_speed) shares the plain one's sampled plant and answers exactly as one built there from the
// configuration; the notch speed map from the model equals the one from the configuration.
TEST(Analysis, ALoopAtASpindleSpeedSharesItsSampledPlantAndAnswersAsOneBuiltThere) {
  const config::Config cfg = c2_with_notches({3, 15.0, 35.0}, 2, 24000.0);
  const analysis::LoopModel plain(cfg);
  const int pol = cfg.controller.polarity;
  const double k = cfg.controller.gain_ns_per_m;
  for (const double rpm : {450.0, 2600.0, 17000.0}) {
    const analysis::LoopModel built(cfg, rpm);
    const analysis::LoopModel shared = plain.at_speed(rpm);
    EXPECT_EQ(&shared.plant(), &plain.plant()) << rpm;
    EXPECT_NE(&built.plant(), &plain.plant()) << rpm;
    ASSERT_EQ(shared.notch_count(), built.notch_count()) << rpm;
    EXPECT_GT(shared.notch_count(), 0U) << rpm;
    EXPECT_EQ(shared.spindle_rpm(), std::optional<double>(rpm));
    EXPECT_EQ(shared.spectral_radius(k, pol), built.spectral_radius(k, pol)) << rpm;
    for (const double f_hz : {3.0, 9.2, 41.0, rpm * 2 / 60.0, 700.0}) {
      EXPECT_EQ(shared.loop_discrete(f_hz, k, pol), built.loop_discrete(f_hz, k, pol)) << rpm << " rpm, " << f_hz;
      EXPECT_EQ(shared.feedback_continuous(f_hz, k, pol), built.feedback_continuous(f_hz, k, pol)) << f_hz;
      EXPECT_EQ(shared.notch_response(f_hz), built.notch_response(f_hz)) << f_hz;
    }
  }
  const analysis::NotchSpeedMap from_cfg = analysis::notch_speed_map(cfg, 60);
  const analysis::NotchSpeedMap from_model = analysis::notch_speed_map(plain, 60);
  ASSERT_EQ(from_model.points.size(), 60U);
  ASSERT_EQ(from_cfg.points.size(), from_model.points.size());
  for (std::size_t i = 0; i < from_cfg.points.size(); ++i) {
    EXPECT_EQ(from_cfg.points[i].spectral_radius, from_model.points[i].spectral_radius) << i;
    EXPECT_EQ(from_cfg.points[i].notch_phase_deg, from_model.points[i].notch_phase_deg) << i;
    EXPECT_EQ(from_cfg.points[i].refused, from_model.points[i].refused) << i;
  }
  EXPECT_EQ(from_cfg.refused_rpm, from_model.refused_rpm);
  EXPECT_THROW((void)analysis::notch_speed_map(plain.at_speed(3000.0)), std::invalid_argument);
}

// Across the speed range: a notch just above the 9.2 Hz mode (tooth frequency 10-14.6 Hz, 20 Hz wide)
// turns the feedback there by up to -118 deg, out of its damping window: those speeds are refused and
// go into the controller's parameters, which then refuse a spindle speed there and park the notches.
TEST(Analysis, NotchSpeedMapRefusesSpeedsThatPushADampedModeOutOfItsWindow) {
  const config::Config cfg = c2_with_notches({4, 20.0, 30.0}, 3, 20000.0);
  const analysis::NotchSpeedMap map = analysis::notch_speed_map(cfg);
  ASSERT_EQ(map.points.size(), 400U);
  EXPECT_NEAR(map.points.front().rpm, 200.0, 1e-9);  // min_hz 10 Hz x 60 / 3 teeth
  ASSERT_EQ(map.refused_rpm.size(), 1U);
  EXPECT_LT(map.refused_rpm[0].first, 200.0);
  EXPECT_GT(map.refused_rpm[0].second, 250.0);
  EXPECT_LT(map.refused_rpm[0].second, 400.0);
  for (const auto& p : map.points) {
    EXPECT_TRUE(p.stable) << p.rpm;
    if (p.refused) {
      EXPECT_NE(p.reason.find("out of its damping window"), std::string::npos) << p.reason;
    }
  }
  control::ControllerParams params = analysis::design_chain(cfg).params;
  analysis::apply_refused_speeds(map, params);
  control::Controller c(params);
  EXPECT_EQ(c.set_spindle_rpm(250.0), control::RequestStatus::kRejectedOutOfRange);
  EXPECT_EQ(c.set_spindle_rpm(12000.0), control::RequestStatus::kAccepted);
  EXPECT_EQ(c.counters().spindle_refused, 1U);
  // More intervals than the controller holds are merged across the smallest gaps, never dropped.
  analysis::NotchSpeedMap many;
  for (int i = 0; i < 12; ++i) many.refused_rpm.emplace_back(1000.0 * i, 1000.0 * i + 100.0 + i);
  analysis::apply_refused_speeds(many, params);
  EXPECT_EQ(params.refused_rpm_count, control::ControllerParams::kMaxRefusedSpeeds);
  EXPECT_EQ(params.refused_rpm[0].first, 0.0);
  EXPECT_EQ(params.refused_rpm[params.refused_rpm_count - 1].second, 11111.0);
}

// Loops no preset describes: C3 at a 2 kHz loop, and C1 on a robot whose modes sit elsewhere, lighter damped.
std::vector<std::pair<std::string, config::Config>> own_loops() {
  std::vector<std::pair<std::string, config::Config>> out;
  for (const char* name : {"horizontal_c1", "horizontal_c2", "horizontal_c3", "tuned_horizontal", "tuned_vertical"})
    out.emplace_back(name, config::load_config_file(test::preset(name)));
  std::string slow = test::read_file(test::preset("horizontal_c3"));
  test::replace_or_throw(slow, "rate_hz: 5000", "rate_hz: 2000");
  out.emplace_back("C3 at 2 kHz", config::parse_config(slow, test::preset("horizontal_c3")));
  std::string moved = test::read_file(test::preset("horizontal_c1"));
  for (const auto& [was, now] :
       {std::pair{"natural_freq_hz: 9.2, damping_ratio: 0.0238", "natural_freq_hz: 13.1, damping_ratio: 0.0110"},
        std::pair{"natural_freq_hz: 9.2, damping_ratio: 0.020",
                  "natural_freq_hz: 13.1, "
                  "damping_ratio: 0.011"},
        std::pair{"natural_freq_hz: 21.0, damping_ratio: 0.0285", "natural_freq_hz: 31.0, damping_ratio: 0.0150"},
        std::pair{"natural_freq_hz: 21.0, damping_ratio: 0.025,", "natural_freq_hz: 31.0, damping_ratio: 0.013,"}})
    test::replace_or_throw(moved, was, now);
  out.emplace_back("C1 on modes of our own", config::parse_config(moved, test::preset("horizontal_c1")));
  return out;
}

// The scan for K_max started from the margins' crossing gain (two or three steps below it, once the poles there
// are checked stable) names the same gain to the bit as the scan from 1 N s/m; the crossing is where the poles
// reach the unit circle (within the bisection's 1e-6); a crossing too high or too low only costs steps.
TEST(Analysis, TheScanForKMaxFromTheMarginsCrossingFindsTheSameGainToTheBit) {
  int hinted = 0;
  for (const auto& [name, cfg] : own_loops()) {
    const analysis::LoopModel m(cfg);
    for (const int pol : {1, -1}) {
      const auto from_one = analysis::max_stable_gain(m, pol);
      const analysis::Margins mg = analysis::margins(m, cfg.controller.gain_ns_per_m, pol, std::nullopt);
      if (!from_one) continue;
      ++hinted;
      ASSERT_TRUE(mg.crossing_gain_ns_per_m) << name << " " << pol;
      EXPECT_NEAR(*mg.crossing_gain_ns_per_m, *from_one, 1e-5 * *from_one) << name << " " << pol;
      EXPECT_EQ(analysis::max_stable_gain(m, pol, mg.crossing_gain_ns_per_m), from_one) << name << " " << pol;
      for (const double wrong : {30.0 * *from_one, 1.3 * *from_one, 0.01 * *from_one, 0.5})
        EXPECT_EQ(analysis::max_stable_gain(m, pol, wrong), from_one) << name << " " << pol << " from " << wrong;
    }
  }
  EXPECT_GE(hinted, 10);
}

// A tune's candidates: loops on one sampled plant (with_controller) share it and its sweeps, and answer exactly
// as loops built alone from their configurations: margins, K_max, the quiet command, the impact's command.
TEST(Analysis, LoopsOnOneSampledPlantShareItsSweepsAndAnswerAsLoopsBuiltAlone) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c1"));
  const analysis::LoopModel first(base);
  analysis::ImpactCommand impact(first, 600.0, 1e-3, std::size_t{1} << 12);
  for (const char* name : {"horizontal_c2", "horizontal_c3"}) {
    const config::Config cfg = config::load_config_file(test::preset(name));
    const analysis::LoopModel shared = first.with_controller(cfg), alone(cfg);
    EXPECT_EQ(&shared.plant(), &first.plant()) << name;
    const analysis::LogGrid grid{0.1, 0.499 * cfg.loop.rate_hz, 6000};
    EXPECT_EQ(shared.plant_sweep(grid), first.plant_sweep(grid)) << name;  // one sweep, computed once
    EXPECT_NE(alone.plant_sweep(grid), first.plant_sweep(grid)) << name;
    const int pol = cfg.controller.polarity;
    for (const double k : {300.0, cfg.controller.gain_ns_per_m}) {
      const analysis::Margins a = analysis::margins(shared, k, pol, std::nullopt),
                              b = analysis::margins(alone, k, pol, std::nullopt);
      EXPECT_EQ(a.phase_margin_deg, b.phase_margin_deg) << name << " " << k;
      EXPECT_EQ(a.delay_margin_ms, b.delay_margin_ms) << name << " " << k;
      EXPECT_EQ(a.phase_crossover_hz, b.phase_crossover_hz) << name << " " << k;
      EXPECT_EQ(a.crossing_gain_ns_per_m, b.crossing_gain_ns_per_m) << name << " " << k;
      EXPECT_EQ(analysis::quiet_command(shared, k, pol).rms_v, analysis::quiet_command(alone, k, pol).rms_v) << name;
      EXPECT_EQ(impact.peak(shared, k, pol).voltage_v, impact.peak(alone, k, pol).voltage_v) << name << " " << k;
    }
    EXPECT_EQ(analysis::max_stable_gain(shared, pol), analysis::max_stable_gain(alone, pol)) << name;
  }
  // The sweep holds response() at each of its points, and two threads asking at once get the one sweep.
  const analysis::LoopModel fresh(base);
  const analysis::LogGrid grid{0.5, 2000.0, 300};
  std::shared_ptr<const std::vector<analysis::PlantResponse>> one, two;
  std::thread t([&] { one = fresh.plant_sweep(grid); });
  two = fresh.plant_sweep(grid);
  t.join();
  ASSERT_EQ(one, two);
  ASSERT_EQ(one->size(), 301U);
  for (const int i : {0, 17, 150, 300}) {
    const analysis::PlantResponse direct = fresh.plant_response(grid.at(i));
    EXPECT_EQ((*one)[static_cast<std::size_t>(i)].accel_per_volt, direct.accel_per_volt) << i;
    EXPECT_EQ((*one)[static_cast<std::size_t>(i)].accel_per_force, direct.accel_per_force) << i;
    EXPECT_EQ((*one)[static_cast<std::size_t>(i)].sensor_response, direct.sensor_response) << i;
  }
  config::Config other_rate = base;
  other_rate.loop.rate_hz = 4000.0;
  EXPECT_THROW((void)first.with_controller(other_rate), std::invalid_argument);
}

}  // namespace
