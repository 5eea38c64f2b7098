#include "analysis/gain_path.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/Householder>

namespace robodamp::analysis {

GainPath::GainPath(const DiscreteSs& unit) {
  const Eigen::Index n = unit.a.rows();
  if (unit.b.cols() != 1 || unit.c.rows() != 1 || unit.b.rows() != n || unit.c.cols() != n)
    throw std::invalid_argument("GainPath: the loop must have one input and one output");
  // P b = beta e1 by one Householder reflection (P symmetric, orthogonal), then P A P to Hessenberg form by
  // reflections that leave e1 alone (Q1 e1 = e1): Q = P Q1 and Q^T b = beta e1.
  Eigen::VectorXd essential(std::max<Eigen::Index>(n - 1, 0));
  double tau = 0.0, beta = 0.0;
  Eigen::VectorXd b = unit.b.col(0);
  b.makeHouseholder(essential, tau, beta);
  Eigen::MatrixXd pap = unit.a;
  Eigen::VectorXd workspace(n);
  pap.applyHouseholderOnTheLeft(essential, tau, workspace.data());
  pap.applyHouseholderOnTheRight(essential, tau, workspace.data());
  Eigen::RowVectorXd cp = unit.c;
  cp.applyHouseholderOnTheRight(essential, tau, workspace.data());
  const Eigen::HessenbergDecomposition<Eigen::MatrixXd> hess(pap);
  h_ = hess.matrixH();
  first_row_ = beta * (cp * Eigen::MatrixXd(hess.matrixQ()));
}

double GainPath::spectral_radius(double gain_ns_per_m, int polarity) const {
  Eigen::MatrixXd h = h_;
  h.row(0) += (polarity * gain_ns_per_m) * first_row_;
  const Eigen::Index n = h.rows();
  const Eigen::RealSchur<Eigen::MatrixXd> schur =
      Eigen::RealSchur<Eigen::MatrixXd>(n).computeFromHessenberg(h, Eigen::MatrixXd::Identity(n, n), false);
  if (schur.info() != Eigen::Success) throw std::runtime_error("GainPath: the QR iterations did not converge");
  const Eigen::MatrixXd& t = schur.matrixT();
  double radius = 0.0;
  for (Eigen::Index i = 0; i < n;) {
    if (i + 1 < n && t(i + 1, i) != 0.0) {  // a 2 x 2 block: a complex pair, or two real values
      const double half_trace = 0.5 * (t(i, i) + t(i + 1, i + 1));
      const double det = t(i, i) * t(i + 1, i + 1) - t(i, i + 1) * t(i + 1, i);
      const double disc = half_trace * half_trace - det;
      radius = std::max(radius, disc < 0.0 ? std::sqrt(det) : std::abs(half_trace) + std::sqrt(disc));
      i += 2;
    } else {
      radius = std::max(radius, std::abs(t(i, i)));
      ++i;
    }
  }
  return radius;
}

}  // namespace robodamp::analysis
