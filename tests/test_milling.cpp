// Stability lobes, the direct test and surface location error against closed forms, hand calculations
// and each other (docs/physics.md §2-3).
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/loop_model.hpp"
#include "config/milling_config.hpp"
#include "milling/lobes.hpp"
#include "milling/sle.hpp"
#include "test_util.hpp"

namespace {

using robodamp::milling::Complex;
namespace cfg = robodamp::config;
namespace mill = robodamp::milling;

std::string milling_preset(const std::string& name) {
  return std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/" + name + ".yaml";
}

using robodamp::test::stiffness_mode;

// One mode in y only: the oriented FRF's eigenvalues are alpha_yy G and 0.
mill::Structure single_y_mode(double fn, double zeta, double k) {
  std::array<std::vector<cfg::ModeConfig>, 4> modes;
  modes[3].push_back(stiffness_mode(fn, zeta, k));
  return mill::Structure(modes, "single mode");
}

struct SingleModeCase {
  const char* name;
  cfg::MillingMode mode;
  double radial_fraction;  // of the diameter
};

class ClosedFormMinimum : public ::testing::TestWithParam<SingleModeCase> {};

TEST_P(ClosedFormMinimum, LobeMinimumMatchesTheSingleModeFormula) {
  const auto c = GetParam();
  const double k = 2.0e7, zeta = 0.03, fn = 600.0, kt = 700.0, kr = 0.3 * kt;
  const int teeth = 3;
  const auto structure = single_y_mode(fn, zeta, k);
  mill::ChatterProcess p;
  p.teeth = teeth;
  p.kt_n_per_m2 = kt * 1e6;
  p.alpha = mill::directional_matrix(mill::engagement(5.0, c.radial_fraction * 10.0, c.mode), kr / kt);
  const double alpha = p.alpha(1, 1);
  // docs/physics.md §2: alpha < 0 (slotting, down/up with large immersion) and alpha > 0.
  const double expected = alpha < 0.0 ? 8.0 * M_PI * k * zeta * (1.0 + zeta) / (teeth * p.kt_n_per_m2 * -alpha)
                                      : 8.0 * M_PI * k * zeta * (1.0 - zeta) / (teeth * p.kt_n_per_m2 * alpha);
  cfg::LobesConfig lc;
  lc.rpm_min = 2000;
  lc.rpm_max = 20000;
  lc.points = 2000;
  const mill::LobeModel model(structure, p, lc);
  const auto d = model.diagram();
  EXPECT_NEAR(d.minimum.b_lim_mm * 1e-3 / expected, 1.0, 5e-3) << c.name << ": alpha_yy = " << alpha;
  // Refined at the speed of the minimum: the grid's interpolation error goes away.
  const auto refined = model.limit_at(d.minimum.rpm);
  ASSERT_TRUE(refined);
  EXPECT_NEAR(refined->b_lim_mm * 1e-3 / expected, 1.0, 2e-3) << c.name;
  EXPECT_GE(refined->b_lim_mm * 1e-3, expected * (1.0 - 1e-9)) << "no depth below the analytic minimum";
}

INSTANTIATE_TEST_SUITE_P(Milling, ClosedFormMinimum,
                         ::testing::Values(SingleModeCase{"slotting", cfg::MillingMode::kDown, 1.0},
                                           SingleModeCase{"half-immersion down milling", cfg::MillingMode::kDown, 0.5},
                                           SingleModeCase{"25% up milling", cfg::MillingMode::kUp, 0.25}),
                         [](const auto& param_info) {
                           return std::string(param_info.index == 0   ? "Slotting"
                                              : param_info.index == 1 ? "HalfDown"
                                                                      : "QuarterUp");
                         });

TEST(Milling, DirectionalFactorsMatchHandValues) {
  const double kr = 0.3;
  // Slotting: alpha_xx = alpha_yy = -pi Kr, alpha_xy = -pi, alpha_yx = pi.
  const auto slot = mill::directional_matrix({0.0, M_PI}, kr);
  EXPECT_NEAR(slot(0, 0), -M_PI * kr, 1e-12);
  EXPECT_NEAR(slot(1, 1), -M_PI * kr, 1e-12);
  EXPECT_NEAR(slot(0, 1), -M_PI, 1e-12);
  EXPECT_NEAR(slot(1, 0), M_PI, 1e-12);
  // Half-immersion down milling: alpha_yy = -1 - pi Kr / 2; 25 % up milling: entry 0, exit 60 deg.
  EXPECT_NEAR(mill::directional_matrix(mill::engagement(5, 5, cfg::MillingMode::kDown), kr)(1, 1), -1.0 - M_PI * kr / 2,
              1e-12);
  const auto up = mill::engagement(5, 2.5, cfg::MillingMode::kUp);
  EXPECT_NEAR(up.exit_rad, M_PI / 3, 1e-12);
  EXPECT_NEAR(mill::directional_matrix(up, kr)(1, 1), 0.5 * (1.5 - kr * (2 * M_PI / 3 + std::sin(2 * M_PI / 3))),
              1e-12);
}

// Lobe points solve det(I + Lambda Phi0) = 0 with Lambda rebuilt from b_lim and the speed, on a
// structure with cross FRFs (mode coupling: Tian et al. (2024), position 3).
TEST(Milling, LobePointsSolveTheCharacteristicEquation) {
  const auto job = cfg::load_milling_config(milling_preset("orthopaedic_bone"));
  const mill::Structure s(*job.find_structure("position_3"), false);
  const mill::LobeModel model(s, mill::chatter_process(job.tool, job.material, job.cut), job.lobes);
  int checked = 0;
  for (int j : {0, 1, 3}) {
    for (const auto& p : model.lobe_points(j)) {
      // Depths a tool can cut; towards a band edge b_lim runs to infinity and rebuilding Lambda from
      // (b, eps) loses digits to 1 - e^{-i eps} with eps -> 0.
      if (p.b_lim_mm > 100.0) continue;
      const Complex d = model.characteristic(p.b_lim_mm, p.rpm, p.chatter_hz);
      // Relative to the size of the terms of the 2x2 determinant (b runs to infinity at band edges).
      const double tau = 60.0 / (job.tool.teeth * p.rpm);
      const double lambda = job.tool.teeth / (4 * M_PI) * job.material.kt_n_per_mm2 * 1e3 * p.b_lim_mm *
                            std::abs(1.0 - std::exp(Complex(0.0, -2 * M_PI * p.chatter_hz * tau)));
      const double scale = 1.0 + lambda * model.oriented(p.chatter_hz).cwiseAbs().maxCoeff();
      EXPECT_LT(std::abs(d) / (scale * scale), 1e-10)
          << "lobe " << j << " at " << p.chatter_hz << " Hz, b " << p.b_lim_mm;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

// The direct test (Nyquist of the characteristic equation, bisection on depth) and the lobes agree on
// the critical depth within 1 %: the industrial robot (37 robot + 9 workpiece modes) and a coupled
// orthopaedic position.
TEST(Milling, DirectTestAgreesWithLobesWithinOnePercent) {
  const auto job = cfg::load_milling_config(milling_preset("industrial_robot_aluminium"));
  const mill::Structure s(*job.find_structure("robot_workpiece"), false);
  const mill::LobeModel model(s, mill::chatter_process(job.tool, job.material, job.cut), job.lobes);
  const auto diagram = model.diagram();
  for (double rpm : {700.0, 1500.0, 4000.0, 10700.0, diagram.minimum.rpm}) {
    const auto zoa = model.limit_at(rpm);
    ASSERT_TRUE(zoa) << rpm;
    const double direct = model.critical_depth_mm(rpm);
    EXPECT_NEAR(direct / zoa->b_lim_mm, 1.0, 0.01)
        << rpm << " rpm: direct " << direct << " mm, lobes " << zoa->b_lim_mm;
    // Just below the lobe the cut is stable, just above it is not.
    EXPECT_TRUE(model.stable(0.99 * zoa->b_lim_mm, rpm)) << rpm;
    EXPECT_FALSE(model.stable(1.01 * zoa->b_lim_mm, rpm)) << rpm;
    // The diagram's interpolated curve is close to the refined value at the same speed.
    if (rpm == diagram.minimum.rpm) {
      EXPECT_NEAR(diagram.minimum.b_lim_mm / zoa->b_lim_mm, 1.0, 0.01);
    }
  }
  const auto bone = cfg::load_milling_config(milling_preset("orthopaedic_bone"));
  const mill::Structure sb(*bone.find_structure("position_4"), false);
  const mill::LobeModel mb(sb, mill::chatter_process(bone.tool, bone.material, bone.cut), bone.lobes);
  for (double rpm : {4000.0, 5500.0, 7000.0}) {
    const auto zoa = mb.limit_at(rpm);
    ASSERT_TRUE(zoa) << rpm;
    EXPECT_NEAR(mb.critical_depth_mm(rpm) / zoa->b_lim_mm, 1.0, 0.01) << rpm;
  }
}

// The sampled controller's closed loop used for chatter (continuous structure, digital chain, one period
// of computation delay, zero-order hold) against the discrete loop that runs, well below Nyquist: the
// same loop gain, and the same change from open to closed loop (the discrete FRFs also carry the
// impact test's own sampling, so their ratio is compared).
TEST(Milling, SampledClosedLoopMatchesTheDiscreteLoop) {
  const robodamp::analysis::LoopModel m(cfg::load_config_file(robodamp::test::preset("horizontal_c2")));
  const double k = m.config().controller.gain_ns_per_m;
  const int pol = m.config().controller.polarity;
  const std::size_t s = m.sensor_location(), a = m.actuator_location();
  for (double f : {6.0, 9.2, 15.0, 23.5, 40.0, 80.0}) {
    const Complex l_sampled = -m.feedback_sampled(f, k, pol) * m.plant().receptance(s, a, f);
    const Complex l_discrete = m.loop_discrete(f, k, pol);
    EXPECT_LT(std::abs(l_sampled - l_discrete), 0.02 * std::abs(1.0 + l_discrete)) << f << " Hz";
    const auto p = m.plant_response(f);
    const Complex ratio_sampled = m.closed_sampled(0, 0, f, k, pol) / m.open_continuous(0, 0, f);
    const Complex ratio_discrete =
        m.closed_discrete(p, m.chain_filters_digital(f), 0, 0, k, pol) / m.open_discrete(p, 0, 0);
    EXPECT_LT(std::abs(ratio_sampled - ratio_discrete), 0.02 * std::abs(ratio_discrete)) << f << " Hz";
  }
}

TEST(Milling, MeanSlottingForcesMatchTheClosedForm) {
  // Straight teeth, slotting: mean Fy = N kt b ft / 4, mean Fx = -N kr b ft / 4 (no edge forces).
  cfg::MaterialConfig mat;
  mat.kt_n_per_mm2 = 600;
  mat.kr_n_per_mm2 = 180;
  const mill::Cutter cutter{cfg::ToolKind::kEndMill, 5.0, 4, 0.0};
  const mill::CutConditions cut{cfg::MillingMode::kDown, 10.0, 2.0, 0.1};
  const auto f = mill::force_spectrum(cutter, mat, cut, 1, 4);
  EXPECT_NEAR(f.fy[0].real(), 4 * 600 * 2.0 * 0.1 / 4, 1e-9);
  EXPECT_NEAR(f.fx[0].real(), -4 * 180 * 2.0 * 0.1 / 4, 1e-9);
  // With a helix and many slices the mean does not change.
  const auto fh = mill::force_spectrum({cfg::ToolKind::kEndMill, 5.0, 4, 0.5}, mat, cut, 50, 4);
  EXPECT_NEAR(fh.fy[0].real(), f.fy[0].real(), 1e-9);
}

// SLE of a single y mode, straight teeth, static and first harmonic only, against a hand calculation:
// Fourier coefficients of Fy by Simpson quadrature of one tooth's force over its engagement, y(t) =
// G(0) F0 + 2 Re(G(w_T) F1 e^{i w_T t}) at the tooth's exit (down) or entry (up).
TEST(Milling, SleOfASingleModeMatchesAHandCalculation) {
  const double k = 1.5e7, zeta = 0.04, fn = 450.0;
  const auto structure = single_y_mode(fn, zeta, k);
  cfg::MaterialConfig mat;
  mat.kt_n_per_mm2 = 700;
  mat.kr_n_per_mm2 = 210;
  mat.kte_n_per_mm = 20;
  mat.kre_n_per_mm = 25;
  const mill::Cutter cutter{cfg::ToolKind::kEndMill, 6.0, 2, 0.0};
  for (auto mode : {cfg::MillingMode::kDown, cfg::MillingMode::kUp}) {
    const mill::CutConditions cut{mode, 3.0, 2.0, 0.1};
    const double rpm = 9000.0, b = cut.axial_mm, ft = cut.feed_per_tooth_mm;
    const auto e = mill::engagement(cutter.radius_mm, cut.radial_mm, mode);
    auto fy = [&](double phi) {
      const double h = ft * std::sin(phi);
      const double Ft = mat.kt_n_per_mm2 * b * h + mat.kte_n_per_mm * b;
      const double Fr = mat.kr_n_per_mm2 * b * h + mat.kre_n_per_mm * b;
      return Ft * std::sin(phi) - Fr * std::cos(phi);
    };
    // F_k = (N / 2 pi) int fy(phi) e^{-i k N phi} dphi over the engagement (one tooth at a time here).
    auto coefficient = [&](int harmonic) {
      const int n = 20000;
      const double hstep = e.width_rad() / n;
      Complex sum(0.0);
      for (int i = 0; i <= n; ++i) {
        const double phi = e.start_rad + i * hstep;
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * fy(phi) * std::exp(Complex(0.0, -harmonic * cutter.teeth * phi));
      }
      return cutter.teeth / (2.0 * M_PI) * sum * hstep / 3.0;
    };
    const double tooth_hz = rpm / 60.0 * cutter.teeth;
    const double wn = 2 * M_PI * fn, w = 2 * M_PI * tooth_hz;
    const Complex g1 = 1.0 / (k * Complex(1.0 - (w / wn) * (w / wn), 2 * zeta * w / wn));
    const double phi_s = mode == cfg::MillingMode::kDown ? M_PI : 0.0;
    const double y =
        coefficient(0).real() / k + 2.0 * (g1 * coefficient(1) * std::polar(1.0, cutter.teeth * phi_s)).real();
    const double expected_um = (mode == cfg::MillingMode::kDown ? 1.0 : -1.0) * y * 1e6;
    const auto r = mill::surface_location_error(structure, cutter, mat, cut, cfg::Axis::kX, rpm, 1, 1);
    EXPECT_NEAR(r.sle_um, expected_um, 1e-6 * std::abs(expected_um) + 1e-9) << cfg::to_string(mode);
    EXPECT_GT(std::abs(expected_um), 1.0) << "a test that could fail";
    // More harmonics change it (the series is not trivially one term), but converge.
    const auto r64 = mill::surface_location_error(structure, cutter, mat, cut, cfg::Axis::kX, rpm, 1, 64);
    const auto r128 = mill::surface_location_error(structure, cutter, mat, cut, cfg::Axis::kX, rpm, 1, 128);
    EXPECT_GT(std::abs(r64.sle_um - r.sle_um), 1e-3);
    EXPECT_NEAR(r64.sle_um, r128.sle_um, 0.01 * std::abs(r128.sle_um) + 0.01);
  }
}

TEST(Milling, FeedAlongYUsesTheXDirectionAsWallNormal) {
  std::array<std::vector<cfg::ModeConfig>, 4> modes;
  modes[0].push_back(stiffness_mode(300.0, 0.05, 1e7));  // xx only
  const mill::Structure s(modes);
  cfg::MaterialConfig mat;
  mat.kt_n_per_mm2 = 600;
  mat.kr_n_per_mm2 = 120;
  const mill::Cutter cutter{cfg::ToolKind::kEndMill, 6.0, 3, 0.5};
  const mill::CutConditions cut{cfg::MillingMode::kDown, 2.0, 2.0, 0.1};
  EXPECT_EQ(mill::surface_location_error(s, cutter, mat, cut, cfg::Axis::kX, 8000, 20, 32).sle_um, 0.0);
  EXPECT_GT(std::abs(mill::surface_location_error(s, cutter, mat, cut, cfg::Axis::kY, 8000, 20, 32).sle_um), 1.0);
}

TEST(Milling, SleCompensationConverges) {
  const auto job = cfg::load_milling_config(milling_preset("industrial_robot_aluminium"));
  const mill::Structure s(*job.find_structure("robot_workpiece"), false);
  const auto cutter = mill::cutter_from(job.tool);
  const auto& c = job.conditions.at(3);  // 2.5 mm axial, 0.25 mm/tooth: the largest error
  const mill::CutConditions cut{job.cut.mode, c.radial_mm, c.axial_mm, c.feed_per_tooth_mm};
  const double offset_um = c.path_offset_y_mm * 1000.0;
  const auto comp = mill::compensate(s, cutter, job.material, cut, cfg::Axis::kX, c.rpm, offset_um, job.sle);
  ASSERT_TRUE(comp.converged);
  EXPECT_GT(comp.error_um.front(), 50.0) << "the uncompensated wall is tens of um off";
  EXPECT_LT(std::abs(comp.residual_um), job.sle.tolerance_um);
  EXPECT_LE(comp.iterations, 5);
  for (std::size_t i = 1; i < comp.error_um.size(); ++i)
    EXPECT_LT(std::abs(comp.error_um[i]), std::abs(comp.error_um[i - 1]));
  // Recomputed independently with the compensated command: the wall is where it was meant to be.
  mill::CutConditions cmd = cut;
  cmd.radial_mm = comp.radial_mm;
  const double sle = mill::surface_location_error(s, cutter, job.material, cmd, cfg::Axis::kX, c.rpm,
                                                  job.sle.axial_slices, job.sle.harmonics)
                         .sle_um;
  EXPECT_LT(std::abs(sle + offset_um - (comp.radial_mm - c.radial_mm) * 1000.0), job.sle.tolerance_um);
}

TEST(Milling, RobotSleIsTensOfMicronsAndNearlySpeedIndependentMachineToolAFew) {
  const auto job = cfg::load_milling_config(milling_preset("industrial_robot_aluminium"));
  const auto cutter = mill::cutter_from(job.tool);
  const mill::CutConditions cut{job.cut.mode, job.cut.radial_mm, job.cut.axial_mm, job.cut.feed_per_tooth_mm};
  const mill::Structure robot(*job.find_structure("robot_workpiece"), false);
  const mill::Structure machine(*job.find_structure("machine_tool"), false);
  double lo = 1e9, hi = -1e9;
  for (double rpm = 2000; rpm <= 12000; rpm += 500) {
    const double v = mill::surface_location_error(robot, cutter, job.material, cut, cfg::Axis::kX, rpm, 40, 64).sle_um;
    lo = std::min(lo, v), hi = std::max(hi, v);
    EXPECT_LT(
        std::abs(mill::surface_location_error(machine, cutter, job.material, cut, cfg::Axis::kX, rpm, 40, 64).sle_um),
        5.0);
  }
  EXPECT_GT(lo, 10.0);
  EXPECT_LT(hi - lo, 0.5 * lo) << "docs/physics.md §3: nearly independent of speed below 12000 rpm";
}

// Configuration errors name the key, the value, the unit and the allowed range.
TEST(Milling, ConfigurationErrorsAreSpecific) {
  const std::string base = robodamp::test::read_file(milling_preset("industrial_robot_aluminium"));
  auto problems_of = [&](const std::string& from, const std::string& to) {
    std::string text = base;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    try {
      (void)cfg::parse_milling_config(text, "job.yaml", std::string(ROBODAMP_SOURCE_DIR) + "/config/milling");
    } catch (const cfg::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string radial = problems_of("  radial_mm: 2\n", "  radial_mm: 14\n");
  EXPECT_NE(radial.find("cut.radial_mm"), std::string::npos) << radial;
  EXPECT_NE(radial.find("= 14 mm is out of range"), std::string::npos) << radial;
  EXPECT_NE(radial.find("tool.diameter_mm = 12.7"), std::string::npos) << radial;
  const std::string teeth = problems_of("teeth: 3", "teeth: 2.5");
  EXPECT_NE(teeth.find("tool.teeth = 2.5 must be a whole number"), std::string::npos) << teeth;
  const std::string both = problems_of("  kn_n_per_mm2: 59.8\n", "  kn_n_per_mm2: 59.8\n  krc_n_per_mm2: 59.8\n");
  EXPECT_NE(both.find("material.krc_n_per_mm2: given together with kn_n_per_mm2"), std::string::npos) << both;
  const std::string zeta = problems_of("damping_ratio: 0.182", "damping_ratio: 1.82");
  EXPECT_NE(zeta.find("structures[0].parts[0].xx[0].damping_ratio = 1.82 (dimensionless) is out of range"),
            std::string::npos)
      << zeta;
  const std::string sel = problems_of("structure: robot_workpiece", "structure: robot_only");
  EXPECT_NE(sel.find("structure = 'robot_only' is not one of the structures: robot_workpiece, machine_tool"),
            std::string::npos)
      << sel;
  const std::string speeds = problems_of("  rpm_max: 15000\n", "  rpm_max: 400\n");
  EXPECT_NE(speeds.find("lobes.rpm_max = 400 rpm must exceed lobes.rpm_min = 500 rpm"), std::string::npos) << speeds;
  const std::string typo = problems_of("  feed_axis: x", "  feed_axes: x");
  EXPECT_NE(typo.find("cut.feed_axes: unknown key"), std::string::npos) << typo;
  // A controller part whose damping configuration is missing.
  const std::string ad = robodamp::test::read_file(milling_preset("active_damping_c2"));
  std::string text = ad;
  text.replace(text.find("config: ../presets/horizontal_c2.yaml"), 37, "config: ../presets/horizontal_c9.yaml");
  try {
    (void)cfg::parse_milling_config(text, "ad.yaml", std::string(ROBODAMP_SOURCE_DIR) + "/config/milling");
    ADD_FAILURE() << "no error";
  } catch (const cfg::ConfigError& e) {
    EXPECT_NE(
        std::string(e.what()).find("controller.config = '../presets/horizontal_c9.yaml': no such file (looked for "),
        std::string::npos)
        << e.what();
  }
}

// The active-damping preset: the controller moves the lobes (model prediction for docs/commands.md).
TEST(Milling, ActiveDampingRaisesTheMinimumStableDepthOfThePreset) {
  const auto job = cfg::load_milling_config(milling_preset("active_damping_c2"));
  const auto& sc = *job.find_structure(job.structure);
  const mill::Structure open(sc, false), closed(sc, true);
  ASSERT_TRUE(closed.has_controller());
  const auto process = mill::chatter_process(job.tool, job.material, job.cut);
  const auto d_open = mill::LobeModel(open, process, job.lobes).diagram();
  const auto d_closed = mill::LobeModel(closed, process, job.lobes).diagram();
  // The robot's 9.2 Hz mode sets the open-loop minimum; the controller damps it.
  EXPECT_NEAR(d_open.minimum.chatter_hz, 9.4, 0.5);
  EXPECT_GT(d_closed.minimum.b_lim_mm, 2.0 * d_open.minimum.b_lim_mm);
}

}  // namespace
