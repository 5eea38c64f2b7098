#include "milling/dominant_multiplier.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>
// GCC 12 reports a use after free inside Spectra's UpperHessenbergEigen (Eigen's aligned_free of a temporary
// in a loop, where the inliner sees the freed pointer reassigned, not used): a false positive of the
// middle-end's -Wuse-after-free on code we do not own. Off for the Spectra headers and this file's use of them.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#include <Spectra/GenEigsSolver.h>
#include <Spectra/MatOp/DenseGenMatProd.h>

namespace robodamp::milling {

std::complex<double> dense_dominant_multiplier(const Eigen::MatrixXd& z) {
  if (z.rows() != z.cols() || z.rows() == 0)
    throw std::invalid_argument("dominant multiplier: the matrix must be square");
  const Eigen::VectorXcd ev = Eigen::EigenSolver<Eigen::MatrixXd>(z, false).eigenvalues();
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < ev.size(); ++i)
    if (std::abs(ev(i)) > std::abs(ev(best))) best = i;
  return ev(best);
}

Eigen::VectorXcd eigenvector_for(const Eigen::MatrixXd& z, std::complex<double> mu) {
  if (z.rows() != z.cols() || z.rows() == 0) throw std::invalid_argument("eigenvector: the matrix must be square");
  const Eigen::Index n = z.rows();
  constexpr int kSolves = 3;
  const double off = 1e-12 * std::max(1.0, z.cwiseAbs().colwise().sum().maxCoeff());
  Eigen::MatrixXcd a = z.cast<std::complex<double>>();
  a.diagonal().array() -= mu + std::complex<double>(off, off);
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(a);
  // A fixed start with every component present (no eigenvector is orthogonal to it but by accident).
  Eigen::VectorXcd v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto x = static_cast<double>(i);
    v(i) = std::complex<double>(1.0 + 0.37 * std::sin(1.3 * x), 0.21 * std::cos(0.7 * x));
  }
  for (int k = 0; k < kSolves; ++k) {
    v = lu.solve(v);
    const double norm = v.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      const Eigen::EigenSolver<Eigen::MatrixXd> es(z, true);
      Eigen::Index best = 0;
      for (Eigen::Index i = 1; i < n; ++i)
        if (std::abs(es.eigenvalues()(i) - mu) < std::abs(es.eigenvalues()(best) - mu)) best = i;
      return es.eigenvectors().col(best);
    }
    v /= norm;
  }
  return v;
}

namespace {

// Arnoldi's largest-magnitude Ritz value and vector of z, or nothing when it does not converge.
bool arnoldi_largest(const Eigen::MatrixXd& z, std::complex<double>& value, Eigen::VectorXcd* vector) {
  Spectra::DenseGenMatProd<double> product(z);
  const auto basis = static_cast<Eigen::Index>(std::min<Eigen::Index>(DominantMultiplier::kBasis, z.rows()));
  Spectra::GenEigsSolver<Spectra::DenseGenMatProd<double>> arnoldi(product, DominantMultiplier::kWanted, basis);
  arnoldi.init();
  const Eigen::Index converged =
      arnoldi.compute(Spectra::SortRule::LargestMagn, DominantMultiplier::kMaxRestarts, DominantMultiplier::kTolerance);
  if (arnoldi.info() != Spectra::CompInfo::Successful || converged < DominantMultiplier::kWanted) return false;
  const Eigen::VectorXcd ev = arnoldi.eigenvalues();  // largest magnitude first
  if (ev.size() == 0 || !std::isfinite(ev(0).real()) || !std::isfinite(ev(0).imag())) return false;
  value = ev(0);
  if (vector) *vector = arnoldi.eigenvectors(1).col(0);
  return true;
}

// The dominant multiplier by Arnoldi on z^(2^kSquarings): moduli that crowd the unit circle spread apart (two
// multipliers 1 % apart in modulus are 8 % apart in z^8), and Arnoldi converges where it gave up on z. Its
// Ritz vector is z's eigenvector for the dominant multiplier, whose Rayleigh quotient in z is the multiplier
// (its argument too, which z^8's eigenvalue has lost); accepted only when that pair's residual in z is at
// round-off.
bool powered_largest(const Eigen::MatrixXd& z, std::complex<double>& mu) {
  Eigen::MatrixXd p = z;
  for (int k = 0; k < DominantMultiplier::kSquarings; ++k) p = (p * p).eval();
  std::complex<double> big;
  Eigen::VectorXcd v;
  if (!arnoldi_largest(p, big, &v)) return false;
  const Eigen::VectorXcd zv = z.cast<std::complex<double>>() * v;
  mu = v.dot(zv) / v.squaredNorm();
  const double residual = (zv - mu * v).norm() / v.norm();
  return std::isfinite(residual) && residual < 1e-9 * std::max(1.0, std::abs(mu));
}

}  // namespace

std::complex<double> DominantMultiplier::operator()(const Eigen::MatrixXd& z) {
  const bool large = z.rows() >= kMinArnoldiSize && z.rows() == z.cols();
  std::complex<double> mu;
  if (large && !arnoldi_gave_up_) {
    if (arnoldi_largest(z, mu, nullptr)) {
      ++arnoldi_;
      return mu;
    }
    arnoldi_gave_up_ = true;
  }
  if (large && !powered_gave_up_) {
    if (powered_largest(z, mu)) {
      ++powered_;
      return mu;
    }
    powered_gave_up_ = true;
  }
  ++dense_;
  return dense_dominant_multiplier(z);
}

}  // namespace robodamp::milling

#pragma GCC diagnostic pop
