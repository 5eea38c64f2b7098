// Time-domain milling (issue 15): the simulated cut against the frequency-domain models on single-mode
// structures (SDM's Floquet multipliers, critical depths in slotting and at 5 % immersion with its flip
// lobes, the zero-order lobes, SLE), SDM's convergence, and the chatter detector below and above the limit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "milling/cut_process.hpp"
#include "milling/cut_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/sdm.hpp"
#include "milling/sle.hpp"
#include "milling/structure.hpp"
#include "test_util.hpp"

namespace {

using namespace robodamp;
using namespace robodamp::milling;

using test::stiffness_mode;

struct Job {
  Structure structure;
  Cutter cutter;
  config::MaterialConfig material;
  config::CutConfig cut;
};

// A 600 Hz mode in y (and in x too unless y_only), 2 straight teeth on a 12 mm cutter, kr/kt = 0.3.
Job single_mode_job(double radial_mm, bool y_only) {
  std::array<std::vector<config::ModeConfig>, 4> modes;
  if (!y_only) modes[0] = {stiffness_mode(600.0, 0.02, 5.6e6)};
  modes[3] = {stiffness_mode(600.0, 0.02, 5.6e6)};
  Job j{Structure(modes), {config::ToolKind::kEndMill, 6.0, 2, 0.0}, {}, {}};
  j.material.kt_n_per_mm2 = 600.0;
  j.material.kr_n_per_mm2 = 180.0;
  j.cut.mode = config::MillingMode::kDown;
  j.cut.radial_mm = radial_mm;
  j.cut.feed_per_tooth_mm = 0.05;
  return j;
}

CutSettings settings_for(const Job& j, double rpm, double axial_mm) {
  CutSettings s;
  s.rpm = rpm;
  s.cut = {j.cut.mode, j.cut.radial_mm, axial_mm, j.cut.feed_per_tooth_mm};
  s.axial_slices = 1;
  s.steps_per_tooth = steps_per_tooth(config::TimeDomainConfig{}, 600.0, rpm, j.cutter.teeth);
  s.revolutions = 80;
  s.settle_revolutions = 30;
  return s;
}

TEST(Sdm, MultiplierConvergesWithTheStepsPerPeriod) {
  const Job j = single_mode_job(1.2, false);
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  std::vector<double> mu;
  for (int m : {20, 40, 80, 160})
    mu.push_back(std::abs(SdmModel(terms, j.cutter, j.material, j.cut.mode, 1.2, 1, m).multiplier(5.0, 12000.0)));
  // Each doubling at least halves the change (first order or better), and the last change is below 0.2 %.
  EXPECT_LT(std::abs(mu[3] - mu[2]), 0.6 * std::abs(mu[2] - mu[1]));
  EXPECT_LT(std::abs(mu[2] - mu[1]), 0.6 * std::abs(mu[1] - mu[0]));
  EXPECT_LT(std::abs(mu[3] - mu[2]), 2e-3);
}

// Below the limit the simulated cut's once-per-tooth differences decay at the rate of SDM's dominant
// Floquet multiplier: the two methods solve the same linearised process.
TEST(Cut, DecayPerToothIsSdmsMultiplier) {
  const Job j = single_mode_job(1.2, true);
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  const SdmModel sdm(terms, j.cutter, j.material, j.cut.mode, 1.2, 1, 80);
  for (double b : {1.0, 2.0, 3.0, 4.0}) {
    CutSettings s = settings_for(j, 12000.0, b);
    s.settle_revolutions = 3, s.revolutions = 23;  // the differences stay well above rounding
    const CutOutcome o = run_cut(terms, j.cutter, j.material, s);
    const double sdm_mu = std::abs(sdm.multiplier(b, 12000.0));
    EXPECT_TRUE(o.verdict.stable) << b;
    EXPECT_NEAR(std::exp(o.verdict.growth_per_period), sdm_mu, 0.01) << b << " mm";
  }
}

// The three methods' critical depths at one speed: zero-order direct test, SDM (40 steps), time domain.
struct ThreeMethods {
  double zoa_mm;
  SdmPoint sdm;
  CriticalDepth td;
};
ThreeMethods three_methods(const Job& j, double rpm) {
  const config::ToolConfig tool{config::ToolKind::kEndMill, 12.0, 2, 0.0};
  const LobeModel lobes(j.structure, chatter_process(tool, j.material, j.cut), config::LobesConfig{});
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  const SdmModel sdm(terms, j.cutter, j.material, j.cut.mode, j.cut.radial_mm, 1, 40);
  const double zoa_mm = lobes.critical_depth_mm(rpm);
  const SdmPoint p = sdm.critical(rpm, zoa_mm);
  return {zoa_mm, p, critical_depth(terms, j.cutter, j.material, settings_for(j, rpm, 1.0), p.critical_depth_mm)};
}

TEST(Cut, SlottingCriticalDepthAgreesWithSdmAndTheZeroOrderLobes) {
  const Job j = single_mode_job(12.0, false);
  for (double rpm : {9000.0, 12000.0, 24000.0}) {
    const auto [zoa_mm, p, td] = three_methods(j, rpm);
    std::printf("slotting %.0f rpm: zero-order %.4f mm, SDM %.4f mm (%s), time domain %.4f mm (%s, %s at %.0f Hz)\n",
                rpm, zoa_mm, p.critical_depth_mm, to_string(p.type), td.depth_mm, to_string(td.mechanism),
                to_string(td.above), td.chatter_hz);
    EXPECT_NEAR(td.depth_mm / p.critical_depth_mm, 1.0, 0.03) << rpm;
    EXPECT_NEAR(p.critical_depth_mm / zoa_mm, 1.0, 0.05) << rpm;
    EXPECT_NEAR(td.chatter_hz, 600.0, 60.0) << rpm;
    EXPECT_EQ(td.mechanism, p.type) << rpm;
  }
}

// Tian et al. (2024)'s observation: above the limit the spectrum has a chatter peak near the structure's mode;
// below it, only the tooth-passing harmonics.
TEST(Cut, ChatterShowsAtTheModeAboveTheLimitAndNotBelow) {
  const Job j = single_mode_job(12.0, false);
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  const double limit_mm =
      SdmModel(terms, j.cutter, j.material, j.cut.mode, 12.0, 1, 40).critical(9000.0, 3.0).critical_depth_mm;
  const CutOutcome below = run_cut(terms, j.cutter, j.material, settings_for(j, 9000.0, 0.8 * limit_mm));
  const CutOutcome above = run_cut(terms, j.cutter, j.material, settings_for(j, 9000.0, 1.2 * limit_mm));
  EXPECT_TRUE(below.verdict.stable);
  EXPECT_EQ(below.verdict.classification, CutClass::kStable);
  EXPECT_LT(below.verdict.nonharmonic_energy_ratio, 1e-3);
  EXPECT_FALSE(above.verdict.stable);
  EXPECT_GT(above.verdict.nonharmonic_energy_ratio, 0.3);
  EXPECT_NEAR(above.verdict.chatter_hz, 600.0, 60.0);
}

TEST(Cut, TimeDomainSettingsAreValidatedLikeEveryKey) {
  const std::string path = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/industrial_robot_aluminium.yaml";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string dir = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling";
  const config::MillingConfig ok = config::parse_milling_config(
      text.str() + "\ntime_domain: {revolutions: 50, settle_revolutions: 10}\n", "job.yaml", dir);
  EXPECT_EQ(ok.time_domain.revolutions, 50);
  EXPECT_EQ(ok.time_domain.min_steps_per_mode_period, 20);
  try {
    (void)config::parse_milling_config(
        text.str() +
            "\ntime_domain: {revolutions: 10, settle_revolutions: 10, runout_um: [1, 2], sdm_steps_per_period: 2, "
            "pitch_deg: [100, 100, 100]}\n",
        "job.yaml", dir);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("time_domain.settle_revolutions = 10 must be less than time_domain.revolutions = 10"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("time_domain.runout_um"), std::string::npos) << what;
    EXPECT_NE(what.find("radial offsets, one per tooth"), std::string::npos) << what;
    EXPECT_NE(what.find("time_domain.sdm_steps_per_period = 2"), std::string::npos) << what;
    EXPECT_NE(what.find("time_domain.pitch_deg: must be a list of 3 angles from each tooth to the next"),
              std::string::npos)
        << what;
  }
}

// A stable cut's wall, simulated, against the frequency-domain SLE (Schmitz-Mann), at speeds whose tooth
// harmonics stay off the 600 Hz mode (at 9 000 rpm the second harmonic is on it: the forced vibration
// makes the edges leave the chip near exit, which the linear frequency-domain model cannot see).
TEST(Cut, StableCutReproducesTheFrequencyDomainSle) {
  Job j = single_mode_job(3.0, false);
  j.material.kte_n_per_mm = 20.0;
  j.material.kre_n_per_mm = 30.0;
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  for (double rpm : {11000.0, 13000.0, 15000.0}) {
    const CutOutcome o = run_cut(terms, j.cutter, j.material, settings_for(j, rpm, 0.5));
    const SleResult f = surface_location_error(j.structure, j.cutter, j.material, {j.cut.mode, 3.0, 0.5, 0.05},
                                               config::Axis::kX, rpm, 1, 64);
    std::printf("SLE at %.0f rpm: time domain %.3f um, frequency domain %.3f um, out of cut %.4f, %s\n", rpm,
                o.record.sle_um, f.sle_um, o.verdict.out_of_cut_share, to_string(o.verdict.classification));
    EXPECT_TRUE(o.verdict.stable) << rpm;
    EXPECT_EQ(o.record.out_of_cut_samples, 0u) << rpm;
    EXPECT_NEAR(o.record.sle_um, f.sle_um, 0.05 * std::abs(f.sle_um)) << rpm;
  }
}

// At 5 % radial immersion the zero-order method misses the period-doubling lobes; SDM and the simulated
// cut find them, and agree on the critical depth.
TEST(Cut, LowImmersionFlipLobesAgreeWithSdm) {
  const Job j = single_mode_job(0.6, false);
  int flips = 0;
  for (double rpm : {13000.0, 20000.0, 24000.0, 38000.0}) {
    const auto [zoa_mm, p, td] = three_methods(j, rpm);
    std::printf(
        "5 %% immersion %.0f rpm: zero-order %.3f mm, SDM %.3f mm (%s, %.0f Hz), time domain %.3f mm (%s, %s at %.0f "
        "Hz)\n",
        rpm, zoa_mm, p.critical_depth_mm, to_string(p.type), p.chatter_hz, td.depth_mm, to_string(td.mechanism),
        to_string(td.above), td.chatter_hz);
    EXPECT_NEAR(td.depth_mm / p.critical_depth_mm, 1.0, 0.03) << rpm;
    EXPECT_EQ(td.mechanism, p.type) << rpm;
    if (p.type == CutClass::kFlip) {
      ++flips;
      EXPECT_GT(zoa_mm, 2.0 * p.critical_depth_mm) << rpm << ": the zero-order method should miss this flip lobe";
    }
  }
  EXPECT_GE(flips, 1);
}

// Runout: the cut repeats once per revolution (not per tooth), the longer tooth takes the thicker chip;
// with runout above the feed the shorter tooth never reaches the material (the tool leaves the cut every
// other pass) and the cut is still stable and periodic.
TEST(Cut, RunoutAndTheToolLeavingTheCutComeFromTheSurfaceMemory) {
  const Job j = single_mode_job(3.0, false);
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  for (double runout_um : {10.0, 60.0}) {
    CutSettings s = settings_for(j, 11000.0, 0.5);
    s.runout_um = {runout_um, 0.0};
    const CutOutcome o = run_cut(terms, j.cutter, j.material, s);
    EXPECT_TRUE(o.verdict.stable) << runout_um;
    EXPECT_LT(o.verdict.nonharmonic_energy_ratio, 1e-3) << runout_um;  // spindle harmonics count as harmonic
    // Peak force of each tooth over the last revolution.
    const std::size_t m = static_cast<std::size_t>(o.record.steps_per_tooth), end = o.record.fy_n.size();
    double peak[2] = {0.0, 0.0};
    for (std::size_t k = end - 2 * m; k < end; ++k) {
      const std::size_t tooth = ((k % (2 * m)) < m) ? 0 : 1;  // tooth 0 sweeps the first half-revolution's bins
      peak[tooth] = std::max(peak[tooth], std::hypot(o.record.fx_n[k], o.record.fy_n[k]));
    }
    const double ft_um = 50.0;
    if (runout_um < ft_um) {
      EXPECT_NEAR(std::max(peak[0], peak[1]) / std::min(peak[0], peak[1]), (ft_um + runout_um) / (ft_um - runout_um),
                  0.15);
      // The short tooth misses the chip only where ft sin(phi) < the runout (near entry and exit).
      EXPECT_GT(o.record.out_of_cut_samples, 0u);
      EXPECT_LT(o.record.out_of_cut_share(), 0.25);
    } else {
      EXPECT_EQ(std::min(peak[0], peak[1]), 0.0);  // the shorter tooth cuts nothing
      EXPECT_NEAR(o.record.out_of_cut_share(), 0.5, 0.02);
    }
  }
}

TEST(Cut, ExponentialForceModelScalesTheCuttingTermsWithTheChip) {
  // A very stiff structure: the chip is the nominal ft sin(phi), so the force follows the model directly.
  std::array<std::vector<config::ModeConfig>, 4> modes;
  modes[0] = {stiffness_mode(600.0, 0.02, 5.6e12)};
  modes[3] = {stiffness_mode(600.0, 0.02, 5.6e12)};
  Job j{Structure(modes), {config::ToolKind::kEndMill, 6.0, 2, 0.0}, {}, {}};
  j.material.kt_n_per_mm2 = 600.0;
  j.material.kr_n_per_mm2 = 180.0;
  j.cut = {config::MillingMode::kDown, 12.0, 1.0, 0.05, config::Axis::kX, 10000.0};
  const auto terms = cutter_modal_terms(j.structure, config::Axis::kX);
  const CutSettings s = settings_for(j, 10000.0, 1.0);
  const CutOutcome linear = run_cut(terms, j.cutter, j.material, s);
  j.material.chip_exponent = 0.3;
  j.material.reference_chip_mm = 0.05;
  const CutOutcome exponential = run_cut(terms, j.cutter, j.material, s);
  // Where the chip is the reference (phi = 90 deg) the two agree; elsewhere the thinner chip cuts harder.
  const std::size_t m = static_cast<std::size_t>(s.steps_per_tooth),
                    k90 = exponential.record.fy_n.size() - 2 * m + m / 2;
  EXPECT_NEAR(exponential.record.fx_n[k90] / linear.record.fx_n[k90], 1.0, 0.01);
  const std::size_t k20 = exponential.record.fy_n.size() - 2 * m + m / 9;  // phi near 20 deg: h = 0.34 ft
  const double chip = std::sin((static_cast<double>(m / 9) + 0.5) * M_PI / static_cast<double>(m));
  EXPECT_NEAR(std::hypot(exponential.record.fx_n[k20], exponential.record.fy_n[k20]) /
                  std::hypot(linear.record.fx_n[k20], linear.record.fy_n[k20]),
              std::pow(chip, -0.3), 0.01);
}

// Uneven pitch: each tooth's chip is the feed since the tooth one pitch ahead passed (pitch / mean pitch x
// the feed per tooth); the cut repeats once per revolution.
TEST(Cut, UnevenPitchGivesEachToothTheFeedOfItsPitch) {
  std::array<std::vector<config::ModeConfig>, 4> modes;
  modes[0] = {stiffness_mode(600.0, 0.02, 5.6e12)};  // stiff: the chip is the nominal one
  modes[3] = {stiffness_mode(600.0, 0.02, 5.6e12)};
  Job j{Structure(modes), {config::ToolKind::kEndMill, 6.0, 2, 0.0}, {}, {}};
  j.material.kt_n_per_mm2 = 600.0;
  j.material.kr_n_per_mm2 = 180.0;
  j.cut = {config::MillingMode::kDown, 12.0, 1.0, 0.05, config::Axis::kX, 10000.0};
  CutSettings s = settings_for(j, 10000.0, 1.0);
  s.steps_per_tooth = 180;  // the pitch angles fall on the 1 degree step grid
  s.pitch_deg = {170.0, 190.0};
  const CutOutcome o = run_cut(cutter_modal_terms(j.structure, config::Axis::kX), j.cutter, j.material, s);
  EXPECT_TRUE(o.verdict.stable);
  const std::size_t end = o.record.fy_n.size(), rev = 360;
  double peak[2] = {0.0, 0.0};
  for (std::size_t k = end - rev; k < end; ++k) {
    const std::size_t tooth = (k % rev) < 180 ? 1 : 0;  // tooth 0 sits at bin 0, tooth 1 at bin 170
    peak[tooth] = std::max(peak[tooth], std::hypot(o.record.fx_n[k], o.record.fy_n[k]));
  }
  EXPECT_NEAR(std::max(peak[0], peak[1]) / std::min(peak[0], peak[1]), 190.0 / 170.0, 0.02);
}

}  // namespace

namespace robodamp::milling {
namespace {

// A 3-tooth helical cutter with runout in half immersion at `rpm`, `axial_mm` deep, 10 slices.
CutSettings changing_cut(double rpm, double axial_mm, int steps_per_tooth) {
  CutSettings s;
  s.rpm = rpm;
  s.cut = {config::MillingMode::kDown, 6.0, axial_mm, 0.1};
  s.axial_slices = 10;
  s.steps_per_tooth = steps_per_tooth;
  s.runout_um = {8.0, 0.0, -3.0};
  return s;
}

const Cutter kHelical{config::ToolKind::kEndMill, 6.0, 3, 30.0 * M_PI / 180.0};

config::MaterialConfig aluminium() {
  config::MaterialConfig m;
  m.kt_n_per_mm2 = 600.0, m.kr_n_per_mm2 = 180.0, m.kte_n_per_mm = 20.0, m.kre_n_per_mm = 10.0;
  return m;
}

// A vibration the cut does not feed back to (prescribed): micrometres at 23 and 61 steps per cycle.
Eigen::Vector2d shake(std::size_t i) {
  const double k = static_cast<double>(i);
  return {2e-6 * std::sin(2.0 * M_PI * k / 23.0), 5e-6 * std::sin(2.0 * M_PI * k / 61.0 + 0.3)};
}

// Steps p from step k for n steps with the displacement shake(i0 + i); the forces.
std::vector<Eigen::Vector2d> step_cut(CutProcess& p, std::size_t k, std::size_t n, std::size_t i0, bool zero = false) {
  std::vector<Eigen::Vector2d> f;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d q = zero ? Eigen::Vector2d::Zero() : shake(i0 + i);
    f.push_back(p.force(k + i, q, true));
    p.end_step(q, q);
  }
  return f;
}

double peak_n(const std::vector<Eigen::Vector2d>& f) {
  double m = 0.0;
  for (const auto& v : f) m = std::max(m, v.norm());
  return m;
}

TEST(CutProcess, ContinuingAtTheSameSpeedAndDepthIsTheSameCut) {
  const CutSettings s = changing_cut(700.0, 1.0, 40);
  CutProcess a(kHelical, aluminium(), s), b(kHelical, aluminium(), s);
  const std::size_t n = 2 * a.steps_per_revolution() + 17;
  (void)step_cut(a, 0, n, 0);
  const std::size_t k = b.continue_from(a, n);
  EXPECT_EQ(k, n % a.steps_per_revolution());
  const auto fa = step_cut(a, n, 3 * a.steps_per_revolution(), n), fb = step_cut(b, k, 3 * a.steps_per_revolution(), n);
  const double scale = peak_n(fa);
  ASSERT_GT(scale, 10.0);
  for (std::size_t i = 0; i < fa.size(); ++i) ASSERT_NEAR((fa[i] - fb[i]).norm() / scale, 0.0, 1e-9) << i;
}

// After a speed change (another step grid), the cut goes on where the surface and the feed left it: with
// the tool still, the force is the steady cut's at the new speed from the first step (within the half
// bin of the surface's angle) and exactly it once the new speed's teeth have cut a revolution.
TEST(CutProcess, ASpeedChangeKeepsTheSurfaceTheAngleAndTheFeed) {
  CutProcess a(kHelical, aluminium(), changing_cut(700.0, 1.0, 40));
  CutProcess b(kHelical, aluminium(), changing_cut(757.0, 1.0, 37)),
      fresh(kHelical, aluminium(), changing_cut(757.0, 1.0, 37));
  const std::size_t n = 3 * a.steps_per_revolution() + 29, per_rev = b.steps_per_revolution();
  (void)step_cut(a, 0, n, 0, true);
  const std::size_t k = b.continue_from(a, n);
  EXPECT_EQ(k, static_cast<std::size_t>(std::lround(29.0 / 120.0 * 111.0)));  // the same spindle angle
  (void)step_cut(fresh, 0, 3 * per_rev + k, 0, true);  // a cut at the new speed only, at the same angle
  const auto fb = step_cut(b, k, 2 * per_rev, 0, true), ff = step_cut(fresh, 3 * per_rev + k, 2 * per_rev, 0, true);
  const double scale = peak_n(ff);
  ASSERT_GT(scale, 10.0);
  for (std::size_t i = 0; i < fb.size(); ++i) {
    const double tolerance = i < per_rev ? 0.02 : 1e-9;  // the old surface's bins, then the new cut's own
    ASSERT_NEAR((fb[i] - ff[i]).norm() / scale, 0.0, tolerance) << i;
  }
}

// A deeper pass meets fresh material above the old depth (the nominal chip there) and the old surface
// below it; a shallower one keeps only the slices it still reaches. Over the first revolution within 8 %
// of the peak (a fresh slice's chip is the nominal one; near the exit, where the chip is the runout's size,
// the steady cut's short tooth skips and the next cuts two feeds: without runout within 2 %), then the same cut.
TEST(CutProcess, ADepthChangeMapsTheSurfaceByHeight) {
  for (const double depth_mm : {2.0, 0.5}) {
    CutProcess a(kHelical, aluminium(), changing_cut(700.0, 1.0, 40));
    CutProcess b(kHelical, aluminium(), changing_cut(700.0, depth_mm, 40)),
        fresh(kHelical, aluminium(), changing_cut(700.0, depth_mm, 40));
    const std::size_t n = 2 * a.steps_per_revolution() + 5, per_rev = b.steps_per_revolution();
    (void)step_cut(a, 0, n, 0, true);
    const std::size_t k = b.continue_from(a, n);
    (void)step_cut(fresh, 0, n, 0, true);
    const auto fb = step_cut(b, k, 2 * per_rev, 0, true), ff = step_cut(fresh, n, 2 * per_rev, 0, true);
    const double scale = peak_n(ff);
    ASSERT_GT(scale, 10.0);
    for (std::size_t i = 0; i < fb.size(); ++i)
      ASSERT_NEAR((fb[i] - ff[i]).norm() / scale, 0.0, i < per_rev ? 0.08 : 1e-9) << depth_mm << " mm, step " << i;
  }
}

}  // namespace
}  // namespace robodamp::milling
