#include "identify/ball_end.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "identify/numeric_csv.hpp"
#include "identify/regression.hpp"
#include "units/units.hpp"

namespace robodamp::identify {

namespace {

constexpr int kKappaPoints = 400;  // Gauss-free midpoint rule over kappa: the integrands are smooth

// The kappa integrals of one run, each already integrated over psi in [0, pi] (slot):
//   int sin^2 = pi/2, int sin = 2, int sin cos = int cos = 0.
// Rows: Fx, Fy, Fz; columns: the unknowns in the order of BallEndCoefficients.
Eigen::Matrix<double, 3, Eigen::Dynamic> regressors(const BallEndTest& t, double a_mm, double c_mm) {
  const double r0 = 0.5 * t.diameter_mm, tanb = std::tan(t.helix_deg * M_PI / 180.0);
  const double kmax = std::acos(1.0 - a_mm / r0);
  const int p = t.order + 1;
  Eigen::Matrix<double, 3, Eigen::Dynamic> m = Eigen::MatrixXd::Zero(3, 3 * p + 3);
  const double dk = kmax / kKappaPoints, scale = t.teeth / (kTwoPi);
  for (int i = 0; i < kKappaPoints; ++i) {
    const double k = (i + 0.5) * dk, sk = std::sin(k), ck = std::cos(k);
    const double shear = c_mm * sk * r0 * dk * scale;                                      // h db / sin(psi)
    const double edge = r0 * std::sqrt(1.0 + std::pow(sk, 4) * tanb * tanb) * dk * scale;  // dS
    double kp = 1.0;
    for (int j = 0; j < p; ++j, kp *= k) {
      m(1, j) += M_PI / 2.0 * shear * kp;               // Ktc_j: Fy
      m(0, p + j) += -sk * M_PI / 2.0 * shear * kp;     // Krc_j: Fx
      m(2, p + j) += ck * 2.0 * shear * kp;             //        Fz
      m(0, 2 * p + j) += ck * M_PI / 2.0 * shear * kp;  // Kac_j: Fx
      m(2, 2 * p + j) += sk * 2.0 * shear * kp;         //        Fz
    }
    m(1, 3 * p) += 2.0 * edge;            // Kte: Fy
    m(0, 3 * p + 1) += -sk * 2.0 * edge;  // Kre: Fx
    m(2, 3 * p + 1) += ck * M_PI * edge;  //      Fz
    m(0, 3 * p + 2) += ck * 2.0 * edge;   // Kae: Fx
    m(2, 3 * p + 2) += sk * M_PI * edge;  //      Fz
  }
  return m;
}

void check(const BallEndTest& t) {
  if (t.order < 0 || t.order > 3)
    throw std::invalid_argument("order = " + std::to_string(t.order) + " is out of range: allowed 0 <= value <= 3");
  if (!(t.teeth >= 1 && t.diameter_mm > 0.0 && t.helix_deg >= 0.0 && t.helix_deg < 90.0))
    throw std::invalid_argument("the tool needs teeth >= 1, a diameter > 0 mm and a helix in [0, 90) deg");
}

}  // namespace

BallEndRun ball_end_mean_forces(const BallEndTest& t, double a_mm, double c_mm, const BallEndCoefficients& c) {
  check(t);
  const auto m = regressors(t, a_mm, c_mm);
  Eigen::VectorXd x(m.cols());
  const int p = t.order + 1;
  for (int j = 0; j < p; ++j) x(j) = c.ktc.at(j), x(p + j) = c.krc.at(j), x(2 * p + j) = c.kac.at(j);
  x(3 * p) = c.kte, x(3 * p + 1) = c.kre, x(3 * p + 2) = c.kae;
  const Eigen::Vector3d f = m * x;
  return {a_mm, c_mm, f(0), f(1), f(2)};
}

BallEndFit identify_ball_end(const std::vector<BallEndRun>& runs, const BallEndTest& t) {
  check(t);
  const int p = t.order + 1;
  const auto n = static_cast<int>(runs.size());
  if (n < p + 2)  // Fy alone: p + 1 unknowns, and a degree of freedom for the intervals
    throw std::invalid_argument("too few runs: " + std::to_string(n) + " for order " + std::to_string(t.order) +
                                " (at least " + std::to_string(p + 2) + ")");
  const double r0 = 0.5 * t.diameter_mm;
  Eigen::MatrixXd xy(n, p + 1), xxz(2 * n, 2 * p + 2);
  Eigen::VectorXd yy(n), yxz(2 * n);
  for (int i = 0; i < n; ++i) {
    const BallEndRun& r = runs[static_cast<std::size_t>(i)];
    for (double v : {r.axial_mm, r.feed_per_tooth_mm, r.fx_n, r.fy_n, r.fz_n})
      if (!std::isfinite(v))
        throw std::invalid_argument("run " + std::to_string(i + 1) + ": a value is not a finite number");
    if (!(r.axial_mm > 0.0 && r.axial_mm <= r0))
      throw std::invalid_argument("run " + std::to_string(i + 1) + ": axial depth " + std::to_string(r.axial_mm) +
                                  " mm is out of range: allowed 0 < value <= the ball's radius " + std::to_string(r0) +
                                  " mm");
    if (!(r.feed_per_tooth_mm > 0.0))
      throw std::invalid_argument("run " + std::to_string(i + 1) + ": the feed per tooth must be > 0 mm");
    const auto m = regressors(t, r.axial_mm, r.feed_per_tooth_mm);
    for (int j = 0; j < p; ++j) xy(i, j) = m(1, j);
    xy(i, p) = m(1, 3 * p);
    yy(i) = r.fy_n;
    for (int row = 0; row < 2; ++row) {
      const int src = row == 0 ? 0 : 2;
      for (int j = 0; j < 2 * p; ++j) xxz(2 * i + row, j) = m(src, p + j);
      xxz(2 * i + row, 2 * p) = m(src, 3 * p + 1);
      xxz(2 * i + row, 2 * p + 1) = m(src, 3 * p + 2);
      yxz(2 * i + row) = row == 0 ? r.fx_n : r.fz_n;
    }
  }
  const Regression a = least_squares(xy, yy), b = least_squares(xxz, yxz);
  BallEndFit f;
  f.runs = n;
  f.condition_number = std::max(a.condition, b.condition);
  if (!(f.condition_number <= kMaxConditionNumber)) {
    std::ostringstream os;
    os << "collinear regressors: the condition number of the regression is " << f.condition_number
       << " (accepted up to " << kMaxConditionNumber << "); the runs cannot separate the order-" << t.order
       << " polynomial's terms: lower --order or add runs at other axial depths and feeds";
    throw std::invalid_argument(os.str());
  }
  for (int j = 0; j < p; ++j) {
    f.ktc.push_back({a.theta(j), a.ci95(j)});
    f.krc.push_back({b.theta(j), b.ci95(j)});
    f.kac.push_back({b.theta(p + j), b.ci95(p + j)});
  }
  f.kte = {a.theta(p), a.ci95(p)};
  f.kre = {b.theta(2 * p), b.ci95(2 * p)};
  f.kae = {b.theta(2 * p + 1), b.ci95(2 * p + 1)};
  f.r2_y = a.tss > 0.0 ? 1.0 - a.rss / a.tss : 1.0;
  f.r2_xz = b.tss > 0.0 ? 1.0 - b.rss / b.tss : 1.0;
  f.residual_rms_n = std::sqrt((a.rss + b.rss) / (3.0 * n));
  return f;
}

std::vector<BallEndRun> read_ball_end_csv(const std::string& path) {
  const std::string header = "axial_mm,feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n";
  const NumericCsv csv = read_numeric_csv(path, header, header, 5);
  std::vector<BallEndRun> out;
  for (const auto& v : csv.rows) out.push_back({v[0], v[1], v[2], v[3], v[4]});
  return out;
}

}  // namespace robodamp::identify
