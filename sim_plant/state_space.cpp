#include "sim_plant/state_space.hpp"

#include <cmath>
#include <stdexcept>

#include <unsupported/Eigen/MatrixFunctions>

namespace robodamp::sim {

namespace {
// [[A, B], [0, 0]] t exponentiates to [[e^{At}, int_0^t e^{As} ds B], [0, I]] (Van Loan).
Zoh block_exp(const Matrix& a, const Matrix& b, double t_s) {
  const Eigen::Index n = a.rows(), m = b.cols();
  Matrix big = Matrix::Zero(n + m, n + m);
  big.topLeftCorner(n, n) = a * t_s;
  big.topRightCorner(n, m) = b * t_s;
  const Matrix e = big.exp();
  return {e.topLeftCorner(n, n), e.topRightCorner(n, m)};
}
}  // namespace

Zoh discretise_zoh(const Matrix& a, const Matrix& b, double h_s) {
  if (!(h_s > 0.0)) throw std::invalid_argument("discretise_zoh: step must be > 0 s");
  return block_exp(a, b, h_s);
}

DelayedZoh discretise_zoh_delayed(const Matrix& a, const Matrix& b, double h_s, double delay_s) {
  if (!(h_s > 0.0) || !(delay_s >= 0.0)) throw std::invalid_argument("discretise_zoh_delayed: bad step or delay");
  DelayedZoh d;
  const double steps = delay_s / h_s;
  double whole = std::floor(steps + 1e-9);
  double frac = steps - whole;
  if (frac < 1e-9) frac = 0.0;
  d.steps = static_cast<int>(whole);
  d.fraction = frac;
  const Zoh full = block_exp(a, b, h_s);
  d.phi = full.phi;
  if (frac == 0.0) {
    d.gamma_late = full.gamma;
    d.gamma_early = Matrix::Zero(full.gamma.rows(), full.gamma.cols());
  } else {
    // The early input acts over [0, f h) and then decays freely for (1 - f) h; the late one acts over
    // the remaining (1 - f) h.
    const Zoh late = block_exp(a, b, (1.0 - frac) * h_s);
    const Zoh early = block_exp(a, b, frac * h_s);
    d.gamma_late = late.gamma;
    d.gamma_early = late.phi * early.gamma;
  }
  return d;
}

}  // namespace robodamp::sim
