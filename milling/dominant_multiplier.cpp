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

std::complex<double> DominantMultiplier::operator()(const Eigen::MatrixXd& z) {
  if (z.rows() >= kMinArnoldiSize && z.rows() == z.cols() && !arnoldi_gave_up_) {
    Spectra::DenseGenMatProd<double> product(z);
    const auto basis = static_cast<Eigen::Index>(std::min<Eigen::Index>(kBasis, z.rows()));
    Spectra::GenEigsSolver<Spectra::DenseGenMatProd<double>> arnoldi(product, kWanted, basis);
    arnoldi.init();
    const Eigen::Index converged = arnoldi.compute(Spectra::SortRule::LargestMagn, kMaxRestarts, kTolerance);
    if (arnoldi.info() == Spectra::CompInfo::Successful && converged >= kWanted) {
      const Eigen::VectorXcd ev = arnoldi.eigenvalues();  // largest magnitude first
      if (ev.size() > 0 && std::isfinite(ev(0).real()) && std::isfinite(ev(0).imag())) {
        ++arnoldi_;
        return ev(0);
      }
    }
    arnoldi_gave_up_ = true;
  }
  ++dense_;
  return dense_dominant_multiplier(z);
}

}  // namespace robodamp::milling

#pragma GCC diagnostic pop
