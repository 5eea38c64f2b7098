#include "identify/cutting_coefficients.hpp"
#include "identify/regression.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "identify/numeric_csv.hpp"
#include "milling/cutting.hpp"
#include "units/units.hpp"

namespace robodamp::identify {

namespace {

// Integrals over the engagement of sin cos, sin^2, cos and sin, and its width.
struct Integrals {
  double sc, ss, c, s, width;
};

Integrals integrals(const CuttingTest& t) {
  const milling::Engagement e = milling::engagement(0.5 * t.diameter_mm, t.radial_mm, t.mode);
  auto at = [](double p) {
    return Integrals{0.5 * std::sin(p) * std::sin(p), 0.5 * p - 0.25 * std::sin(2.0 * p), std::sin(p), -std::cos(p), p};
  };
  const Integrals a = at(e.start_rad), b = at(e.exit_rad);
  return {b.sc - a.sc, b.ss - a.ss, b.c - a.c, b.s - a.s, b.width - a.width};
}

void check_test(const CuttingTest& t) {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (t.teeth < 1 || t.teeth > 32)
    bad("teeth = " + std::to_string(t.teeth) + " is out of range: allowed 1 <= value <= 32");
  if (!(t.diameter_mm > 0.0 && t.diameter_mm <= 200.0)) bad("diameter must be 0 < value <= 200 mm");
  if (!(t.axial_mm > 0.0 && t.axial_mm <= 100.0)) bad("axial depth must be 0 < value <= 100 mm");
  if (!(t.radial_mm > 0.0 && t.radial_mm <= t.diameter_mm)) bad("radial depth must be 0 < value <= the diameter");
}

}  // namespace

MeanForces mean_forces(const CuttingTest& t, double c, double ktc, double krc, double kac, double kte, double kre,
                       double kae) {
  const Integrals i = integrals(t);
  const double k = t.teeth * t.axial_mm / (kTwoPi);
  return {c, k * (-ktc * c * i.sc - krc * c * i.ss - kte * i.c - kre * i.s),
          k * (ktc * c * i.ss - krc * c * i.sc + kte * i.s - kre * i.c), k * (kac * c * i.s + kae * i.width)};
}

CuttingFit identify_cutting(const std::vector<MeanForces>& samples, const CuttingTest& t) {
  check_test(t);
  const auto n = static_cast<Eigen::Index>(samples.size());
  if (n < 3)
    throw std::invalid_argument("too few feeds: " + std::to_string(n) +
                                " given, at least 3 needed (6 unknowns, and "
                                "degrees of freedom left for the confidence intervals)");
  for (Eigen::Index r = 0; r < n; ++r) {
    const MeanForces& s = samples[static_cast<std::size_t>(r)];
    if (!std::isfinite(s.feed_per_tooth_mm) || !std::isfinite(s.fx_n) || !std::isfinite(s.fy_n) ||
        !std::isfinite(s.fz_n))
      throw std::invalid_argument("row " + std::to_string(r + 1) + ": a value is not a finite number");
    if (!(s.feed_per_tooth_mm > 0.0))
      throw std::invalid_argument("row " + std::to_string(r + 1) + ": feed per tooth must be > 0 mm");
  }
  const Integrals i = integrals(t);
  const double k = t.teeth * t.axial_mm / (kTwoPi);
  // x and y rows: unknowns [Ktc, Krc, Kte, Kre]; z rows: [Kac, Kae].
  Eigen::MatrixXd xy(2 * n, 4), z(n, 2);
  Eigen::VectorXd fxy(2 * n), fz(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const MeanForces& s = samples[static_cast<std::size_t>(r)];
    const double c = s.feed_per_tooth_mm;
    xy.row(2 * r) << -k * c * i.sc, -k * c * i.ss, -k * i.c, -k * i.s;
    xy.row(2 * r + 1) << k * c * i.ss, -k * c * i.sc, k * i.s, -k * i.c;
    fxy(2 * r) = s.fx_n, fxy(2 * r + 1) = s.fy_n;
    z.row(r) << k * c * i.s, k * i.width;
    fz(r) = s.fz_n;
  }
  const Regression a = least_squares(xy, fxy), b = least_squares(z, fz);
  CuttingFit f;
  f.condition_number = std::max(a.condition, b.condition);
  if (!(f.condition_number <= kMaxConditionNumber)) {
    std::ostringstream os;
    os << "collinear regressors: the condition number of the regression is " << f.condition_number
       << " (allowed <= " << kMaxConditionNumber
       << "); the feeds are too close together to separate the cutting coefficients from the edge ones";
    throw std::invalid_argument(os.str());
  }
  f.ktc = {a.theta(0), a.ci95(0)}, f.krc = {a.theta(1), a.ci95(1)}, f.kte = {a.theta(2), a.ci95(2)},
  f.kre = {a.theta(3), a.ci95(3)};
  f.kac = {b.theta(0), b.ci95(0)}, f.kae = {b.theta(1), b.ci95(1)};
  f.r2_xy = a.tss > 0.0 ? 1.0 - a.rss / a.tss : 1.0;
  const Eigen::VectorXd fitted = xy * a.theta;
  for (int axis = 0; axis < 2; ++axis) {
    double mean = 0.0, rss = 0.0, tss = 0.0;
    for (Eigen::Index r = 0; r < n; ++r) mean += fxy(2 * r + axis) / static_cast<double>(n);
    for (Eigen::Index r = 0; r < n; ++r)
      rss += std::pow(fxy(2 * r + axis) - fitted(2 * r + axis), 2), tss += std::pow(fxy(2 * r + axis) - mean, 2);
    (axis == 0 ? f.r2_x : f.r2_y) = tss > 0.0 ? 1.0 - rss / tss : 1.0;
  }
  f.r2_z = b.tss > 0.0 ? 1.0 - b.rss / b.tss : 1.0;
  f.residual_rms_n = std::sqrt((a.rss + b.rss) / static_cast<double>(3 * n));
  f.samples = static_cast<int>(n);
  return f;
}

std::vector<MeanForces> read_mean_forces_csv(const std::string& path) {
  const std::string header = "feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n";
  std::vector<MeanForces> out;
  for (const auto& r : read_numeric_csv(path, header, header, 4).rows) out.push_back({r[0], r[1], r[2], r[3]});
  return out;
}

}  // namespace robodamp::identify
