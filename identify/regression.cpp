#include "identify/regression.hpp"

#include <cmath>

namespace robodamp::identify {

// Student's t at 97.5 % for dof degrees of freedom (tabulated to 30, then the normal quantile's series).
double t975(int dof) {
  static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                 2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                 2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof >= 1 && dof <= 30) return table[dof - 1];
  const double z = 1.959964, n = dof;  // Cornish-Fisher expansion, error < 1e-4 beyond 30
  return z + (z * z * z + z) / (4.0 * n) + (5.0 * std::pow(z, 5) + 16.0 * z * z * z + 3.0 * z) / (96.0 * n * n);
}

Regression least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  Regression r;
  const Eigen::VectorXd norms = x.colwise().norm();
  const Eigen::MatrixXd scaled = x * norms.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled);
  const auto& sv = svd.singularValues();
  r.condition = sv(sv.size() - 1) > 0.0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  r.theta = x.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd residual = y - x * r.theta;
  r.rss = residual.squaredNorm();
  r.tss = (y.array() - y.mean()).matrix().squaredNorm();
  const auto dof = static_cast<int>(x.rows() - x.cols());
  const Eigen::MatrixXd cov = (r.rss / dof) * (x.transpose() * x).inverse();
  r.ci95 = t975(dof) * cov.diagonal().cwiseSqrt();
  return r;
}

}  // namespace robodamp::identify
