#include "milling/interval_collocation.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace robodamp::milling {

namespace {

constexpr double kInterpolationTolerance = 1e-15;

// exp(t a) of a 2 x 2 block as exp(s t) (c(t) I + sh(t) N), s half the trace, N = a - s I, N^2 = delta I.
struct BlockExp {
  explicit BlockExp(const Eigen::Matrix2d& a) : s(0.5 * a.trace()) {
    n = a - s * Eigen::Matrix2d::Identity();
    delta = n(0, 0) * n(0, 0) + n(0, 1) * n(1, 0);
  }
  // exp(s t), cosh(sqrt(delta) t) and sinh(sqrt(delta) t) / sqrt(delta) (cos and sin where delta < 0).
  void factors(double t, double& e, double& c, double& sh) const {
    e = std::exp(s * t);
    const double z = delta * t * t;
    if (std::abs(z) < 1e-3) {  // the series: the next terms are below 1e-18
      c = 1.0 + z * (1.0 / 2 + z * (1.0 / 24 + z * (1.0 / 720 + z / 40320)));
      sh = t * (1.0 + z * (1.0 / 6 + z * (1.0 / 120 + z * (1.0 / 5040 + z / 362880))));
    } else if (delta > 0.0) {
      const double r = std::sqrt(delta);
      c = std::cosh(r * t), sh = std::sinh(r * t) / r;
    } else {
      const double r = std::sqrt(-delta);
      c = std::cos(r * t), sh = std::sin(r * t) / r;
    }
  }
  [[nodiscard]] Eigen::Matrix2d at(double t) const {
    double e = 0.0, c = 0.0, sh = 0.0;
    factors(t, e, c, sh);
    return e * (c * Eigen::Matrix2d::Identity() + sh * n);
  }
  double s, delta{0.0};
  Eigen::Matrix2d n;
};

// The Lagrange polynomials of nodes x (in [-1, 1]) at t, by the barycentric formula.
class Lagrange {
 public:
  explicit Lagrange(Eigen::VectorXd x) : x_(std::move(x)), w_(x_.size()) {
    for (Eigen::Index j = 0; j < x_.size(); ++j) {
      double prod = 1.0;
      for (Eigen::Index k = 0; k < x_.size(); ++k)
        if (k != j) prod *= x_(j) - x_(k);
      w_(j) = 1.0 / prod;
    }
  }
  void at(double t, Eigen::VectorXd& l) const {
    l.resize(x_.size());
    double sum = 0.0;
    for (Eigen::Index j = 0; j < x_.size(); ++j) {
      if (t == x_(j)) {
        l.setZero();
        l(j) = 1.0;
        return;
      }
      l(j) = w_(j) / (t - x_(j));
      sum += l(j);
    }
    l /= sum;
  }

 private:
  Eigen::VectorXd x_, w_;
};

}  // namespace

Quadrature gauss_legendre(int points, double length) {
  if (points < 1) throw std::invalid_argument("gauss_legendre: needs at least one point");
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(points, points);
  for (int k = 1; k < points; ++k) {
    const double beta = k / std::sqrt(4.0 * k * k - 1.0);
    jacobi(k, k - 1) = jacobi(k - 1, k) = beta;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(jacobi);
  Quadrature q;
  q.nodes = (es.eigenvalues().array() + 1.0) * (0.5 * length);
  q.weights = es.eigenvectors().row(0).transpose().array().square() * length;  // 2 v0^2 on [-1, 1], times L / 2
  return q;
}

Eigen::Matrix2d exp2x2(const Eigen::Matrix2d& a, double t) { return BlockExp(a).at(t); }

int IntervalCollocation::nodes_for(double rho_h) {
  double bound = 2.0;
  for (int p = 1; p <= kMaxNodes; ++p) {
    bound *= rho_h / (4.0 * p);
    if (p >= kMinNodes && bound < kInterpolationTolerance) return p;
  }
  return 0;
}

IntervalCollocation::IntervalCollocation(const std::vector<Eigen::Matrix2d>& blocks, const Eigen::MatrixXd& b,
                                         const Eigen::MatrixXd& c, double h, int nodes,
                                         std::vector<Eigen::Matrix2d> free)
    : n_(static_cast<Eigen::Index>(2 * blocks.size())), p_(nodes), free_(std::move(free)) {
  if (p_ < 1 || p_ > kMaxNodes) throw std::invalid_argument("IntervalCollocation: nodes must be 1-64");
  if (b.rows() != n_ || b.cols() != 2 || c.rows() != 2 || c.cols() != n_ || free_.size() != blocks.size())
    throw std::invalid_argument("IntervalCollocation: B must be n x 2, C 2 x n, one free block per mode");
  tables(blocks, b, c, h);
}

// The three tables of one interval length, one quadrature each.
void IntervalCollocation::tables(const std::vector<Eigen::Matrix2d>& blocks, const Eigen::MatrixXd& b,
                                 const Eigen::MatrixXd& c, double h) {
  const Quadrature s = gauss_legendre(p_, h);
  u_ = s.nodes / h;
  const Lagrange lagrange((2.0 * u_.array() - 1.0).matrix());
  const auto on_nodes = [&](double t, Eigen::VectorXd& l) { lagrange.at(2.0 * t / h - 1.0, l); };
  std::vector<BlockExp> modes;
  std::vector<Eigen::Matrix2d> cb, cnb;  // C_k B_k and C_k N_k B_k: the impulse response's terms
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(2 * k);
    modes.emplace_back(blocks[k]);
    cb.emplace_back(c.middleCols(r, 2) * b.middleRows(r, 2));
    cnb.emplace_back(c.middleCols(r, 2) * modes.back().n * b.middleRows(r, 2));
  }
  const auto blocks_n = static_cast<Eigen::Index>(blocks.size());
  q_.resize(2 * p_, n_);
  for (int j = 0; j < p_; ++j)
    for (Eigen::Index k = 0; k < blocks_n; ++k)
      q_.block(2 * j, 2 * k, 2, 2) = c.middleCols(2 * k, 2) * modes[static_cast<std::size_t>(k)].at(s.nodes(j));
  // Quadratures of twice the nodes: exact for the Lagrange polynomial times the exponential's own
  // interpolant of degree p - 1.
  const int points = 2 * p_;
  const Quadrature unit = gauss_legendre(points, 1.0);
  Eigen::VectorXd l;
  v_ = Eigen::MatrixXd::Zero(n_, 2 * p_);
  for (int r = 0; r < points; ++r) {
    const double t = unit.nodes(r) * h, wt = unit.weights(r) * h;
    on_nodes(t, l);
    for (Eigen::Index k = 0; k < blocks_n; ++k) {
      const Eigen::Matrix2d e = modes[static_cast<std::size_t>(k)].at(h - t) * b.middleRows(2 * k, 2);
      for (int j = 0; j < p_; ++j) v_.block(2 * k, 2 * j, 2, 2) += (wt * l(j)) * e;
    }
  }
  w_ = Eigen::MatrixXd::Zero(2 * p_, 2 * p_);
  for (int j = 0; j < p_; ++j) {
    const double sj = s.nodes(j);
    for (int r = 0; r < points; ++r) {
      const double t = unit.nodes(r) * sj, wt = unit.weights(r) * sj, tau = sj - t;
      Eigen::Matrix2d response = Eigen::Matrix2d::Zero();
      for (std::size_t k = 0; k < modes.size(); ++k) {
        double e = 0.0, ch = 0.0, sh = 0.0;
        modes[k].factors(tau, e, ch, sh);
        response += e * (ch * cb[k] + sh * cnb[k]);
      }
      on_nodes(t, l);
      for (int i = 0; i < p_; ++i) w_.block(2 * j, 2 * i, 2, 2) += (wt * l(i)) * response;
    }
  }
  p_cut_.resize(n_, 2 * p_);
  s_cut_.resize(2 * p_, 2 * p_);
}

void IntervalCollocation::set_cut(const Eigen::Matrix2d& m) {
  for (int l = 0; l < p_; ++l) {
    p_cut_.middleCols(2 * l, 2).noalias() = v_.middleCols(2 * l, 2) * m;
    s_cut_.middleCols(2 * l, 2).noalias() = -w_.middleCols(2 * l, 2) * m;
  }
  s_cut_.diagonal().array() += 1.0;
  lu_.compute(s_cut_);
}

}  // namespace robodamp::milling
