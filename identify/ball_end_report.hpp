// What `robodamp identify cutting --ball-end` reports (docs/identification.md): the shear coefficients of a
// ball-end mill as polynomials in the axial angle kappa and the edge coefficients, with their 95 % intervals,
// R^2, the residual RMS and the condition number, as text, JSON and a `material:` block (the coefficients at
// kappa = 1 rad, as Tian et al. (2024) tabulate the ball-end bone study's). Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "identify/ball_end.hpp"

namespace robodamp::identify {

// The axial angle at which the `material:` block and the text's single values read the polynomials, rad.
inline constexpr double kBallEndTableKappaRad = 1.0;

// A polynomial's value at kappa (rad): k0 + k1 kappa + ...
[[nodiscard]] double polynomial_at(const std::vector<Estimate>& poly, double kappa_rad);

struct BallEndReport {
  nlohmann::json json;
  std::string text;  // the coefficients, the fit's figures, a note where an interval is wider than its value
  std::string yaml;  // the material: block
};

// source: what the runs came from (the CSV's path), named in the block.
[[nodiscard]] BallEndReport ball_end_report(const BallEndFit& f, const BallEndTest& t, const std::string& source);

}  // namespace robodamp::identify
