// Cutting coefficients of a ball-end mill from slot-milling mean forces (the ball-end bone study's method, docs/physics.md
// section 4 in docs/identification.md's words). An edge point at axial angle kappa (0 at the tip) of a
// ball of radius R0 cuts a chip h = c sin(kappa) sin(psi) over a width db = R0 dkappa along an edge
// element dS = R0 sqrt(1 + sin^4(kappa) tan^2(beta0)) dkappa, with
//   dFt = Kte dS + Ktc(kappa) h db,  dFr = Kre dS + Krc(kappa) h db,  dFa = Kae dS + Kac(kappa) h db,
// the shear coefficients polynomials in kappa of the chosen order (the ball-end bone study: cubic), the edge ones constant;
// projected on the tool frame
//   dFx = -cos(psi) dFt - sin(k) sin(psi) dFr + cos(k) sin(psi) dFa,
//   dFy =  sin(psi) dFt - sin(k) cos(psi) dFr + cos(k) cos(psi) dFa,
//   dFz =  cos(k) dFr + sin(k) dFa.
// Over a revolution the mean force is (N / 2 pi) times the integral over kappa in [0, kappa_max(a)] and the
// slot's engagement psi in [0, pi]: linear in the unknowns. The helix's lag only shifts psi and drops out
// of a mean; beta0 enters through dS alone. Fy gives Ktc(kappa) and Kte; Fx and Fz give the radial and
// axial ones. Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include "identify/cutting_coefficients.hpp"

namespace robodamp::identify {

struct BallEndRun {
  double axial_mm{0.0};
  double feed_per_tooth_mm{0.0};
  double fx_n{0.0}, fy_n{0.0}, fz_n{0.0};
};

struct BallEndTest {
  int teeth{8};
  double diameter_mm{4.0};
  double helix_deg{30.0};
  int order{3};  // of the shear coefficients' polynomial in kappa (rad), 0..3
};

struct BallEndFit {
  std::vector<Estimate> ktc, krc, kac;  // polynomial terms k0 + k1 kappa + ..., N/mm^2 (per rad^i)
  Estimate kte, kre, kae;               // N/mm
  double r2_y{0.0}, r2_xz{0.0};
  double residual_rms_n{0.0};
  double condition_number{0.0};  // the larger of the two regressions', columns scaled
  int runs{0};
};

// The unknowns: Ktc_0..order, Krc_0..order, Kac_0..order, Kte, Kre, Kae.
struct BallEndCoefficients {
  std::vector<double> ktc, krc, kac;
  double kte{0.0}, kre{0.0}, kae{0.0};
};

// The forward model (mean forces of a slot at this axial depth and feed); tests and synthetic data.
[[nodiscard]] BallEndRun ball_end_mean_forces(const BallEndTest& t, double axial_mm, double feed_per_tooth_mm,
                                              const BallEndCoefficients& c);

// Throws std::invalid_argument: too few runs for the unknowns, a non-finite value (its row), an axial depth
// beyond the ball's radius, a test out of range, or a condition number above kMaxConditionNumber (named,
// with the advice to lower the order).
[[nodiscard]] BallEndFit identify_ball_end(const std::vector<BallEndRun>& runs, const BallEndTest& t);

// Reads `axial_mm,feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n` (header required).
[[nodiscard]] std::vector<BallEndRun> read_ball_end_csv(const std::string& path);

}  // namespace robodamp::identify
