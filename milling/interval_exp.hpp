// The matrix exponential of one semi-discretization interval, using its structure (docs/milling.md,
// "Semi-discretization", "How fast"). Over an interval of length h with the directional matrix M held, the
// state x of the structure's modes (2 x 2 blocks A_k), the delayed displacement q_d and its slope r obey
//   d/dt [x; q_d; r] = X [x; q_d; r],  X = [[A + U C, -U, 0], [0, 0, I], [0, 0, 0]],  U = B M,
// X = blockdiag(A, shift) + L R with L = [U; 0] and R = [C, -I, 0] of rank 2, so X times a dense matrix costs
// ~12 N^2 operations instead of 2 N^3 (N = n + 4). exp(h X) by Higham's scaling and squaring with the
// [13/13] Pade approximant (the method of Eigen's MatrixExponential, which this replaces): the powers and
// the approximant's polynomials by structured products, one LU solve, s dense squarings. Before it, a
// diagonal similarity by powers of two (Parlett and Reinsch's balancing: exact) evens out the rows and
// columns: a mode's velocity, the cut's stiffness (1e6-1e8 N/m) and displacements in metres meet in X,
// and the balanced norm needs fewer squarings. Off the real-time path.
#pragma once

#include <vector>

#include <Eigen/Dense>

namespace robodamp::milling {

class IntervalExp {
 public:
  // A's 2 x 2 diagonal blocks, C (2 x n): the structure's continuous model (n = 2 x blocks).
  IntervalExp(std::vector<Eigen::Matrix2d> blocks, Eigen::MatrixXd c);

  // exp(h X) for this U (n x 2), into e (N x N, resized once).
  void compute(const Eigen::MatrixXd& u, double h, Eigen::MatrixXd& e);
  // exp(h A) (the interval without cutting: U = 0) as its blocks.
  [[nodiscard]] std::vector<Eigen::Matrix2d> free_blocks(double h) const;
  // The squarings the last compute() needed.
  [[nodiscard]] int squarings() const { return squarings_; }

 private:
  // y = X x for the current (scaled, balanced) structure; y is resized.
  void apply(const Eigen::MatrixXd& x, Eigen::MatrixXd& y) const;
  void balance();
  [[nodiscard]] double norm1() const;

  std::vector<Eigen::Matrix2d> a0_;  // the structure's blocks
  Eigen::MatrixXd c0_;               // and outputs
  Eigen::Index n_{0}, size_{0};
  // The current X = blockdiag(a_) + l_ r_ + shift (rows n, n+1 take shift_ times rows n+2, n+3).
  std::vector<Eigen::Matrix2d> a_;
  Eigen::MatrixXd l_, r_;
  Eigen::Vector2d shift_;
  Eigen::VectorXd d_;  // the balancing similarity's diagonal
  mutable Eigen::MatrixXd rx_;
  Eigen::MatrixXd dense_, a2_, a4_, a6_, t1_, t2_, u_, v_;
  int squarings_{0};
};

}  // namespace robodamp::milling
