// Linear state-space models and their exact zero-order-hold discretisation (matrix exponential), with an
// input delay that need not be a whole number of steps. Off the real-time path.
#pragma once

#include <Eigen/Dense>

namespace robodamp::sim {

using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

// x' = A x + B u, y = C x + D u.
struct StateSpace {
  Matrix a, b, c, d;
};

// x[k+1] = phi x[k] + gamma u[k] for u held over the step: phi = e^{A h}, gamma = int_0^h e^{A s} ds B.
struct Zoh {
  Matrix phi, gamma;
};
[[nodiscard]] Zoh discretise_zoh(const Matrix& a, const Matrix& b, double h_s);

// Inputs delayed by tau = (steps + fraction) h and held: over step k the delayed input is u[k-steps-1]
// for the first fraction * h and u[k-steps] for the rest, so (modified z-transform, exact)
//   x[k+1] = phi x[k] + gamma_early u[k-steps-1] + gamma_late u[k-steps].
struct DelayedZoh {
  Matrix phi, gamma_early, gamma_late;
  int steps{0};
  double fraction{0.0};
};
[[nodiscard]] DelayedZoh discretise_zoh_delayed(const Matrix& a, const Matrix& b, double h_s, double delay_s);

}  // namespace robodamp::sim
