// Linear state-space models and their exact zero-order-hold discretisation (matrix exponential), with an
// input delay that need not be a whole number of steps. Off the real-time path except SparseRows::apply.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

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

// Which entries of e^{A t} can be non-zero: state j reaches state i through the graph of A.
[[nodiscard]] Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> reachability(const Matrix& a);

// Compressed rows of a matrix with a known sparsity pattern, for allocation-free products.
class SparseRows {
 public:
  SparseRows() = default;
  // Keeps the entries where pattern is true (or every non-zero entry without a pattern).
  SparseRows(const Matrix& m, const Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic>* pattern = nullptr);
  // out = M x. RT-safe.
  void apply(const double* x, double* out) const noexcept {
    const std::size_t rows = row_start_.size() - 1;
    for (std::size_t r = 0; r < rows; ++r) out[r] = row_dot(r, x);
  }
  [[nodiscard]] std::size_t nonzeros() const { return value_.size(); }
  // One row of M x. RT-safe.
  [[nodiscard]] double row_dot(std::size_t r, const double* x) const noexcept {
    double acc = 0.0;
    for (std::uint32_t i = row_start_[r], end = row_start_[r + 1]; i < end; ++i) acc += value_[i] * x[column_[i]];
    return acc;
  }
  [[nodiscard]] std::size_t rows() const { return row_start_.empty() ? 0 : row_start_.size() - 1; }

 private:
  std::vector<std::uint32_t> row_start_;
  std::vector<std::uint32_t> column_;
  std::vector<double> value_;
};

}  // namespace robodamp::sim
