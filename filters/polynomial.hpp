// Real polynomials in the Laplace variable s: the numerators and denominators of continuous blocks.
#pragma once

#include <complex>
#include <vector>

namespace robodamp::filters {

using Complex = std::complex<double>;

// c[0] + c[1] s + ... + c[n] s^n. Leading zero coefficients are trimmed, so degree() is exact.
class Polynomial {
 public:
  Polynomial() = default;
  explicit Polynomial(std::vector<double> ascending);

  // Coefficients as printed in papers and in our YAML: highest power first.
  static Polynomial from_descending(const std::vector<double>& descending);
  // Monic product of (s - r) over the roots (complex roots must come in conjugate pairs), times gain.
  static Polynomial from_roots(const std::vector<Complex>& roots, double gain);

  [[nodiscard]] int degree() const { return static_cast<int>(c_.size()) - 1; }
  [[nodiscard]] bool is_zero() const { return c_.size() == 1 && c_[0] == 0.0; }
  [[nodiscard]] double leading() const { return c_.back(); }
  [[nodiscard]] double coefficient(int power) const;
  [[nodiscard]] const std::vector<double>& ascending() const { return c_; }
  [[nodiscard]] std::vector<double> descending() const;
  [[nodiscard]] bool all_finite() const;

  [[nodiscard]] Complex evaluate(Complex s) const;
  // Roots from the eigenvalues of the companion matrix (Eigen's PolynomialSolver), with conjugate
  // pairs made exactly conjugate and near-real roots made real, so the pairing into sections is exact.
  [[nodiscard]] std::vector<Complex> roots() const;
  // Number of roots at s = 0 (trailing zero coefficients), removed exactly by drop_roots_at_zero.
  [[nodiscard]] int roots_at_zero() const;
  [[nodiscard]] Polynomial drop_roots_at_zero(int count) const;

  friend Polynomial operator*(const Polynomial& a, const Polynomial& b);

 private:
  void trim();
  std::vector<double> c_{0.0};
};

}  // namespace robodamp::filters
