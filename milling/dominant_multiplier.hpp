// The Floquet multiplier of largest magnitude of a monodromy matrix, for the depth searches of the accurate
// methods (milling/sdm.hpp, milling/sampled_sdm.hpp; docs/milling.md, "How fast"). A search needs only that
// one eigenvalue at each depth, not the whole spectrum a dense QR gives (Eigen's EigenSolver: a Hessenberg
// reduction and Francis steps, 45 % of the sampled loop's SDM). Implicitly restarted Arnoldi (Spectra's
// GenEigsSolver, the method of ARPACK; a fixed starting vector, so the same matrix gives the same answer)
// finds it from products of the matrix with vectors when the multipliers near the unit circle are few, as
// in the damped loop, whose controller damps most of its modes within a tooth period. When they crowd the
// circle (the 46 lightly damped modes of the industrial robot over a short tooth period) Arnoldi needs
// hundreds of restarts: after kMaxRestarts without convergence it gives up, and Arnoldi on z^8 (three
// squarings, which spread the crowded moduli apart) answers with its Ritz vector's Rayleigh quotient in z,
// checked by its residual in z. Only when that fails too does the dense QR answer. A method that gave up stays
// given up for this object's later calls (the rest of one speed's search). On the 46-mode robot's diagram the
// powered Arnoldi answers every one of the 1166 matrices the dense QR answered before, the depths the same to
// 1e-14. Off the real-time path.
#pragma once

#include <complex>

#include <Eigen/Dense>

namespace robodamp::milling {

class DominantMultiplier {
 public:
  static constexpr Eigen::Index kMinArnoldiSize = 60;  // below, the dense QR is as fast
  static constexpr int kWanted = 4;                    // Ritz values converged: a complex pair and the next
  static constexpr int kBasis = 40;                    // Arnoldi basis
  static constexpr int kMaxRestarts = 10;
  static constexpr double kTolerance = 1e-12;  // relative residual of the converged Ritz values
  static constexpr int kSquarings = 3;         // Arnoldi's second try on z^8

  // The eigenvalue of largest magnitude of the square matrix z (of a complex pair, either).
  [[nodiscard]] std::complex<double> operator()(const Eigen::MatrixXd& z);

  [[nodiscard]] int arnoldi_answers() const { return arnoldi_; }
  [[nodiscard]] int powered_answers() const { return powered_; }
  [[nodiscard]] int dense_answers() const { return dense_; }

 private:
  bool arnoldi_gave_up_{false};
  bool powered_gave_up_{false};
  int arnoldi_{0}, powered_{0}, dense_{0};
};

// By the dense QR alone (Eigen's EigenSolver): the reference the tests compare with.
[[nodiscard]] std::complex<double> dense_dominant_multiplier(const Eigen::MatrixXd& z);

// The eigenvector of z for its eigenvalue mu (known to round-off, as above), by inverse iteration: a few
// solves with one complex LU of z - mu I, the shift moved off mu by 1e-12 of z's norm so the LU is not exactly
// singular (each solve then multiplies the wanted direction by its gap to the next eigenvalue over 1e-12).
// The critical Floquet mode's chatter frequency needs only this vector: a dense QR with vectors took twice
// the eigenvalues' time (30 ms at 172 states against 3.5 ms here). Falls back to the dense QR's vector when
// the iteration does not settle (a non-finite solve). Off the real-time path.
[[nodiscard]] Eigen::VectorXcd eigenvector_for(const Eigen::MatrixXd& z, std::complex<double> mu);

}  // namespace robodamp::milling
