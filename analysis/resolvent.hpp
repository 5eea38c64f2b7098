// C (z I - Phi)^-1 B at many points z of the unit circle, for the loop model's frequency responses.
// Phi is diagonalised once (Phi = V diag(lambda) V^-1): each z then costs O(n m) instead of an O(n^3)
// LU of z I - Phi. Where the eigenvectors are ill-conditioned (a defective or nearly defective Phi, e.g.
// repeated modes) it keeps the LU at every z. Off the real-time path.
#pragma once

#include <complex>

#include <Eigen/Dense>

namespace robodamp::analysis {

class Resolvent {
 public:
  // Beyond this condition number of V the diagonal form's rounding (about cond(V) * 1e-16) is not
  // accepted and every z solves the LU.
  static constexpr double kMaxCondition = 1e6;

  Resolvent() = default;
  Resolvent(const Eigen::MatrixXd& phi, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c);

  // C (z I - Phi)^-1 B (rows of C by columns of B).
  [[nodiscard]] Eigen::MatrixXcd operator()(std::complex<double> z) const;
  [[nodiscard]] bool diagonal() const { return diagonal_; }

 private:
  Eigen::MatrixXd phi_, b_, c_;  // for the LU
  bool diagonal_{false};
  Eigen::VectorXcd lambda_;
  Eigen::MatrixXcd c_v_, v_inv_b_;  // C V and V^-1 B
};

}  // namespace robodamp::analysis
