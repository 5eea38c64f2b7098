// Cutting coefficients of a flat end mill from mean forces (Altintas' mechanistic model, docs/physics.md
// section 2; docs/identification.md): with the chip h = c sin(phi) of a tooth at phi,
//   Ft = Ktc a h + Kte a,  Fr = Krc a h + Kre a,  Fa = Kac a h + Kae a,
// the force on the tool in the cutter frame (x along the feed, y normal to it, z along the tool axis,
// tooth angle phi clockwise from +y as in milling/cutting.hpp) is
//   Fx = -Ft cos(phi) - Fr sin(phi),  Fy = Ft sin(phi) - Fr cos(phi),  Fz = Fa,
// and its mean over a revolution is linear in the feed per tooth c: slope from the cutting coefficients,
// intercept from the edge ones, for any radial immersion and milling mode (the helix does not change the
// mean). A least-squares fit over several feeds gives all six with 95 % confidence intervals, R^2, the
// residual RMS and the regression's condition number; ill-posed data is refused, never reported as a fit.
// Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/milling_config.hpp"

namespace robodamp::identify {

struct MeanForces {
  double feed_per_tooth_mm{0.0};
  double fx_n{0.0}, fy_n{0.0}, fz_n{0.0};
};

struct CuttingTest {
  int teeth{3};
  double diameter_mm{12.7};
  double axial_mm{1.0};
  double radial_mm{12.7};
  config::MillingMode mode{config::MillingMode::kDown};
};

struct Estimate {
  double value{0.0};
  double ci95{0.0};  // half-width of the 95 % confidence interval
};

struct CuttingFit {
  Estimate ktc, krc, kac;  // N/mm^2
  Estimate kte, kre, kae;  // N/mm
  double r2_xy{0.0}, r2_z{0.0};
  double r2_x{0.0}, r2_y{0.0};  // each axis alone (r2_z is z alone)
  double residual_rms_n{0.0};
  double condition_number{0.0};  // of the feed-force regression, columns scaled to unit length
  int samples{0};
};

// The largest condition number accepted: above it the feeds are too close to separate the cutting
// coefficients from the edge ones.
inline constexpr double kMaxConditionNumber = 1e4;

// The mean forces the model gives (the forward model the fit inverts; tests and synthetic data).
[[nodiscard]] MeanForces mean_forces(const CuttingTest& test, double feed_per_tooth_mm, double ktc, double krc,
                                     double kac, double kte, double kre, double kae);

// Throws std::invalid_argument naming what is wrong: too few feeds, a non-finite value (its row), a test
// outside its ranges, or collinear regressors (with the condition number).
[[nodiscard]] CuttingFit identify_cutting(const std::vector<MeanForces>& samples, const CuttingTest& test);

// Whether each axis's mean force is linear in the feed, as the model says: a quadratic in the feed fitted
// beside the line; an axis is not linear when its curvature is significant at 95 % and moves the force by
// more than 1 % of its largest value within the feeds. Needs 4 feeds or more (none checked below).
struct LinearityCheck {
  char axis{'x'};
  double r2{1.0};  // of the line
  bool linear{true};
  std::vector<std::pair<double, double>> residuals_n;  // feed (mm), measured minus the line (N)
  double linear_up_to_mm{0.0};                         // the feeds up to here fit a line (0: no three do)
  std::optional<CuttingFit> linear_range_fit;          // the fit over those feeds
  std::string message;                                 // empty when linear
};
[[nodiscard]] std::vector<LinearityCheck> check_linearity(const std::vector<MeanForces>& samples,
                                                          const CuttingTest& test, const CuttingFit& fit);

// Reads `feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n` (header required); throws std::invalid_argument
// with the file and line of the first problem.
[[nodiscard]] std::vector<MeanForces> read_mean_forces_csv(const std::string& path);

}  // namespace robodamp::identify
