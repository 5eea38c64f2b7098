#pragma once
// The closed loop's poles along its gain, fast: the discrete loop closed at gain K is A + K b c (one input,
// one output, b a column). Reduced once to the controller-Hessenberg form (an orthogonal Q with Q^T b = beta e1
// and H = Q^T A Q upper Hessenberg), the closed loop Q^T (A + K b c) Q = H + K beta e1 (c Q) differs from H only
// in its first row and stays Hessenberg: each gain costs the QR iterations alone, not the reduction that takes
// most of a dense eigenvalue solve. The same eigenvalues as LoopModel::closed_loop_poles (an orthogonal
// similarity), to rounding.
#include <Eigen/Core>

#include "analysis/loop_model.hpp"

namespace robodamp::analysis {

class GainPath {
 public:
  // The loop's unit open loop (LoopModel::open_loop_unit): a, b (n x 1), c (1 x n).
  explicit GainPath(const DiscreteSs& unit);
  // The largest pole modulus of the loop closed at gain_ns_per_m and polarity (LoopModel::spectral_radius).
  [[nodiscard]] double spectral_radius(double gain_ns_per_m, int polarity) const;

 private:
  Eigen::MatrixXd h_;             // Q^T A Q, upper Hessenberg
  Eigen::RowVectorXd first_row_;  // beta (c Q): the closed loop adds K polarity times this to H's first row
};

}  // namespace robodamp::analysis
