// Linear least squares with the quality figures every identification reports (docs/identification.md):
// the estimate, 95 % confidence intervals (Student's t over the residual variance and (X^T X)^-1), the
// residual and total sums of squares, and the condition number of X with its columns scaled to unit length.
#pragma once

#include <Eigen/Dense>

namespace robodamp::identify {

// Student's t at 97.5 % for dof degrees of freedom.
[[nodiscard]] double t975(int dof);

struct Regression {
  Eigen::VectorXd theta, ci95;
  double rss{0.0}, tss{0.0}, condition{0.0};
};

// x: rows = observations; needs more rows than columns.
[[nodiscard]] Regression least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y);

}  // namespace robodamp::identify
