#include "analysis/resolvent.hpp"

#include <Eigen/Eigenvalues>

namespace robodamp::analysis {

Resolvent::Resolvent(const Eigen::MatrixXd& phi, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c)
    : phi_(phi), b_(b), c_(c) {
  if (phi.rows() == 0) return;
  const Eigen::EigenSolver<Eigen::MatrixXd> es(phi, true);
  if (es.info() != Eigen::Success) return;
  const Eigen::MatrixXcd v = es.eigenvectors();
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(v);
  const Eigen::MatrixXcd v_inv = lu.inverse();
  const double condition = v.cwiseAbs().colwise().sum().maxCoeff() * v_inv.cwiseAbs().colwise().sum().maxCoeff();
  if (!(condition < kMaxCondition)) return;
  lambda_ = es.eigenvalues();
  c_v_ = c.cast<std::complex<double>>() * v;
  v_inv_b_ = v_inv * b.cast<std::complex<double>>();
  diagonal_ = true;
}

Eigen::MatrixXcd Resolvent::operator()(std::complex<double> z) const {
  if (diagonal_) {
    const Eigen::VectorXcd w = (z - lambda_.array()).inverse();
    return c_v_ * (w.asDiagonal() * v_inv_b_);
  }
  Eigen::MatrixXcd m = -phi_.cast<std::complex<double>>();
  m.diagonal().array() += z;
  return c_.cast<std::complex<double>>() * m.partialPivLu().solve(b_.cast<std::complex<double>>());
}

}  // namespace robodamp::analysis
