// One semi-discretization interval of a many-mode structure as the free flight plus a low-rank correction
// (docs/milling.md, "How fast"). Over an interval of length h with the directional matrix M held, the modes'
// state x (2 x 2 blocks A_k, input B, output C) and the delayed displacement qd(t), linear from q_o at t = 0
// to q_no at t = h, obey
//   x' = A x + B M w,  w(t) = C x(t) - qd(t).
// The cut feeds back only through the two-dimensional w, which solves a Volterra equation of the second kind
//   w(s) = C e^{sA} x0 - qd(s) + integral_0^s C e^{(s - t)A} B M w(t) dt
// whose kernel is the structure's impulse response. Collocating w on p Gauss-Legendre nodes s_j of the
// interval (w a polynomial of degree p - 1 there) gives
//   x(h) = F x0 + P S^-1 (Q x0 - D q),  F = e^{hA} (block diagonal),
// Q = [C e^{s_j A}] (2p x n), P = [V_l M] (n x 2p), S = I - [W_jl M] (2p x 2p),
//   V_l = integral_0^h e^{(h - t)A} B l_l(t) dt,  W_jl = integral_0^s_j C e^{(s_j - t)A} B l_l(t) dt,
// l_l the Lagrange polynomials of the nodes. Q, V and W depend on h alone; M enters as 2 x 2 products. Carrying
// n + 2m columns through the interval then costs about 8 p (n + 2m) n operations instead of the dense
// exponential's LU, solves and squarings on n + 4 (2 (n + 4)^3 each) and its n x n product.
// The nodes: w is a combination of e^{lambda s} with |lambda| <= rho, rho bounding the interval's matrix
// A + B M C; interpolating such a function on p nodes errs by about 2 (rho h / 4)^p / p! (Chebyshev's bound on
// the Bernstein ellipse), and p is the smallest with that below 1e-15. For a short interval against the highest
// mode (high speeds, many modes) p is 10-20; for a long one it grows and the dense exponential is cheaper.
// Off the real-time path.
#pragma once

#include <vector>

#include <Eigen/Dense>

namespace robodamp::milling {

// Gauss-Legendre nodes and weights on [0, length] (Golub and Welsch), nodes in increasing order.
struct Quadrature {
  Eigen::VectorXd nodes, weights;
};
[[nodiscard]] Quadrature gauss_legendre(int points, double length);

// exp(t a) of a real 2 x 2 matrix in closed form (its trace and determinant; the series where its two
// eigenvalues nearly meet).
[[nodiscard]] Eigen::Matrix2d exp2x2(const Eigen::Matrix2d& a, double t);

class IntervalCollocation {
 public:
  static constexpr int kMinNodes = 4;  // the fewest nodes a collocation takes
  static constexpr int kMaxNodes = 64;

  // The nodes a collocation needs for an interval of length h whose matrix is bounded by rho (1/s), or 0 when
  // more than kMaxNodes would.
  [[nodiscard]] static int nodes_for(double rho_h);

  // A's 2 x 2 diagonal blocks, B (n x 2), C (2 x n), the interval h (s), the nodes p, and exp(h A_k) as the
  // caller's free flight takes it (the same blocks, so a cutting and a free interval agree where M -> 0).
  IntervalCollocation(const std::vector<Eigen::Matrix2d>& blocks, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c,
                      double h, int nodes, std::vector<Eigen::Matrix2d> free);

  // The interval's directional matrix (N/m): forms P and S's LU.
  void set_cut(const Eigen::Matrix2d& m);
  // out = x(h) for the columns x0 (n x k), q_o and q_no (2 x k each), with the M of the last set_cut().
  template <typename X, typename Qo, typename Qno, typename Out>
  void step(const X& x0, const Qo& q_o, const Qno& q_no, Out&& out);

  [[nodiscard]] int nodes() const { return p_; }

 private:
  void tables(const std::vector<Eigen::Matrix2d>& blocks, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c, double h);

  Eigen::Index n_{0};
  int p_{0};
  std::vector<Eigen::Matrix2d> free_;
  Eigen::VectorXd u_;          // the nodes as fractions of h
  Eigen::MatrixXd q_, v_, w_;  // 2p x n, n x 2p, 2p x 2p
  Eigen::MatrixXd p_cut_, s_cut_, y_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

template <typename X, typename Qo, typename Qno, typename Out>
void IntervalCollocation::step(const X& x0, const Qo& q_o, const Qno& q_no, Out&& out) {
  y_.noalias() = q_ * x0;
  for (int j = 0; j < p_; ++j) {
    const double u = u_(j);
    y_.middleRows(2 * j, 2) -= (1.0 - u) * q_o + u * q_no;
  }
  y_ = lu_.solve(y_);
  for (std::size_t k = 0; k < free_.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(2 * k);
    out.middleRows(r, 2).noalias() = free_[k] * x0.middleRows(r, 2);
  }
  out.noalias() += p_cut_ * y_;
}

}  // namespace robodamp::milling
