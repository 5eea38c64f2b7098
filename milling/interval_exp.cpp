#include "milling/interval_exp.hpp"

#include <cmath>
#include <stdexcept>

#include <unsupported/Eigen/MatrixFunctions>

namespace robodamp::milling {

namespace {

// Higham (2005): the [13/13] Pade approximant's coefficients and the 1-norm up to which it is accurate to
// double precision without squaring.
constexpr double kPade13[14] = {64764752532480000.0,
                                32382376266240000.0,
                                7771770303897600.0,
                                1187353796428800.0,
                                129060195264000.0,
                                10559470521600.0,
                                670442572800.0,
                                33522128640.0,
                                1323241920.0,
                                40840800.0,
                                960960.0,
                                16380.0,
                                182.0,
                                1.0};
constexpr double kTheta13 = 5.371920351148152;

}  // namespace

IntervalExp::IntervalExp(std::vector<Eigen::Matrix2d> blocks, Eigen::MatrixXd c)
    : a0_(std::move(blocks)), c0_(std::move(c)), n_(static_cast<Eigen::Index>(2 * a0_.size())), size_(n_ + 4) {
  if (c0_.rows() != 2 || c0_.cols() != n_) throw std::invalid_argument("IntervalExp: C must be 2 x (2 x blocks)");
  a_ = a0_;
  l_ = Eigen::MatrixXd::Zero(size_, 2);
  r_ = Eigen::MatrixXd::Zero(2, size_);
}

std::vector<Eigen::Matrix2d> IntervalExp::free_blocks(double h) const {
  std::vector<Eigen::Matrix2d> out;
  out.reserve(a0_.size());
  for (const Eigen::Matrix2d& a : a0_) out.emplace_back((a * h).exp());
  return out;
}

void IntervalExp::apply(const Eigen::MatrixXd& x, Eigen::MatrixXd& y) const {
  y.resize(size_, x.cols());
  rx_.noalias() = r_ * x;  // 2 x cols
  const std::size_t blocks = a_.size();
  for (Eigen::Index j = 0; j < x.cols(); ++j) {  // column by column: x and y are column-major
    const double* xj = x.col(j).data();
    double* yj = y.col(j).data();
    const double r0 = rx_(0, j), r1 = rx_(1, j);
    for (std::size_t k = 0; k < blocks; ++k) {
      const Eigen::Matrix2d& a = a_[k];
      const std::size_t i = 2 * k;
      const double x0 = xj[i], x1 = xj[i + 1];
      yj[i] = a(0, 0) * x0 + a(0, 1) * x1 + l_(static_cast<Eigen::Index>(i), 0) * r0 +
              l_(static_cast<Eigen::Index>(i), 1) * r1;
      yj[i + 1] = a(1, 0) * x0 + a(1, 1) * x1 + l_(static_cast<Eigen::Index>(i + 1), 0) * r0 +
                  l_(static_cast<Eigen::Index>(i + 1), 1) * r1;
    }
    yj[n_] = shift_(0) * xj[n_ + 2];
    yj[n_ + 1] = shift_(1) * xj[n_ + 3];
    yj[n_ + 2] = yj[n_ + 3] = 0.0;
  }
}

void IntervalExp::balance() {
  d_ = Eigen::VectorXd::Ones(size_);
  for (bool changed = true; changed;) {
    changed = false;
    for (Eigen::Index i = 0; i < size_; ++i) {
      double c = dense_.col(i).cwiseAbs().sum() - std::abs(dense_(i, i));
      double r = dense_.row(i).cwiseAbs().sum() - std::abs(dense_(i, i));
      if (c == 0.0 || r == 0.0) continue;
      const double before = c + r;
      double f = 1.0;
      while (c < 0.5 * r) c *= 2.0, r *= 0.5, f *= 2.0;
      while (c >= 2.0 * r) c *= 0.5, r *= 2.0, f *= 0.5;
      if (c + r >= 0.95 * before) continue;
      changed = true;
      d_(i) *= f;
      dense_.row(i) /= f;
      dense_.col(i) *= f;
    }
  }
  // The same similarity on the structured form: X' = D^-1 X D.
  for (std::size_t k = 0; k < a_.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(2 * k);
    const Eigen::Vector2d di = d_.segment(i, 2);
    a_[k] = di.cwiseInverse().asDiagonal() * a_[k] * di.asDiagonal();
  }
  l_.array().colwise() /= d_.array();
  r_.array().rowwise() *= d_.transpose().array();
  shift_(0) *= d_(n_ + 2) / d_(n_), shift_(1) *= d_(n_ + 3) / d_(n_ + 1);
}

double IntervalExp::norm1() const { return dense_.cwiseAbs().colwise().sum().maxCoeff(); }

// long: Higham's [13/13] scaling and squaring written out on the structured products (one formula)
void IntervalExp::compute(const Eigen::MatrixXd& u, double h, Eigen::MatrixXd& e) {
  if (u.rows() != n_ || u.cols() != 2) throw std::invalid_argument("IntervalExp: U must be n x 2");
  // h X, then balanced.
  for (std::size_t k = 0; k < a0_.size(); ++k) a_[k] = a0_[k] * h;
  l_.setZero();
  l_.topRows(n_) = u * h;
  r_.setZero();
  r_.leftCols(n_) = c0_;
  r_.block(0, n_, 2, 2) = -Eigen::Matrix2d::Identity();
  shift_.setConstant(h);
  dense_ = Eigen::MatrixXd::Zero(size_, size_);
  for (std::size_t k = 0; k < a_.size(); ++k)
    dense_.block(static_cast<Eigen::Index>(2 * k), static_cast<Eigen::Index>(2 * k), 2, 2) = a_[k];
  dense_.topRows(n_).noalias() += l_.topRows(n_) * r_;
  dense_(n_, n_ + 2) = shift_(0), dense_(n_ + 1, n_ + 3) = shift_(1);
  balance();
  const double norm = norm1();
  squarings_ = norm > kTheta13 ? static_cast<int>(std::ceil(std::log2(norm / kTheta13))) : 0;
  if (squarings_ > 0) {
    const double scale = std::ldexp(1.0, -squarings_);
    for (Eigen::Matrix2d& a : a_) a *= scale;
    l_ *= scale, shift_ *= scale, dense_ *= scale;
  }
  const double* b = kPade13;
  apply(dense_, a2_);
  apply(a2_, t1_), apply(t1_, a4_);
  apply(a4_, t1_), apply(t1_, a6_);
  auto times_a6 = [&] {  // t1_ = X^6 t1_
    for (int i = 0; i < 6; ++i) apply(t1_, t2_), t1_.swap(t2_);
  };
  t1_ = b[12] * a6_ + b[10] * a4_ + b[8] * a2_;
  times_a6();
  v_ = t1_ + b[6] * a6_ + b[4] * a4_ + b[2] * a2_;
  v_.diagonal().array() += b[0];
  t1_ = b[13] * a6_ + b[11] * a4_ + b[9] * a2_;
  times_a6();
  t1_ += b[7] * a6_ + b[5] * a4_ + b[3] * a2_;
  t1_.diagonal().array() += b[1];
  apply(t1_, u_);
  t1_ = v_ - u_;
  t2_ = v_ + u_;
  e = t1_.partialPivLu().solve(t2_);
  for (int i = 0; i < squarings_; ++i) t1_.noalias() = e * e, e.swap(t1_);
  e = d_.asDiagonal() * e * d_.cwiseInverse().asDiagonal();
}

}  // namespace robodamp::milling
