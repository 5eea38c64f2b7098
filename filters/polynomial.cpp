#include "filters/polynomial.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Core>
#include <unsupported/Eigen/Polynomials>

namespace robodamp::filters {

Polynomial::Polynomial(std::vector<double> ascending) : c_(std::move(ascending)) {
  if (c_.empty()) c_.push_back(0.0);
  trim();
}

Polynomial Polynomial::from_descending(const std::vector<double>& descending) {
  return Polynomial(std::vector<double>(descending.rbegin(), descending.rend()));
}

Polynomial Polynomial::from_roots(const std::vector<Complex>& roots, double gain) {
  std::vector<Complex> c{Complex(1.0)};
  for (const Complex& r : roots) {
    std::vector<Complex> next(c.size() + 1, Complex(0.0));
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i + 1] += c[i];
      next[i] -= r * c[i];
    }
    c = std::move(next);
  }
  std::vector<double> real(c.size());
  std::transform(c.begin(), c.end(), real.begin(), [gain](Complex v) { return gain * v.real(); });
  return Polynomial(std::move(real));
}

void Polynomial::trim() {
  while (c_.size() > 1 && c_.back() == 0.0) c_.pop_back();
}

double Polynomial::coefficient(int power) const {
  return (power >= 0 && power < static_cast<int>(c_.size())) ? c_[static_cast<std::size_t>(power)] : 0.0;
}

std::vector<double> Polynomial::descending() const { return {c_.rbegin(), c_.rend()}; }

bool Polynomial::all_finite() const {
  return std::all_of(c_.begin(), c_.end(), [](double v) { return std::isfinite(v); });
}

Complex Polynomial::evaluate(Complex s) const {
  Complex acc(0.0);
  for (auto it = c_.rbegin(); it != c_.rend(); ++it) acc = acc * s + *it;  // Horner
  return acc;
}

int Polynomial::roots_at_zero() const {
  if (is_zero()) return 0;
  int n = 0;
  while (c_[static_cast<std::size_t>(n)] == 0.0) ++n;
  return n;
}

Polynomial Polynomial::drop_roots_at_zero(int count) const {
  if (count > roots_at_zero()) throw std::logic_error("drop_roots_at_zero: not that many roots at s = 0");
  return Polynomial(std::vector<double>(c_.begin() + count, c_.end()));
}

std::vector<Complex> Polynomial::roots() const {
  const int zeros_at_origin = roots_at_zero();
  const Polynomial reduced = drop_roots_at_zero(zeros_at_origin);
  std::vector<Complex> out(static_cast<std::size_t>(zeros_at_origin), Complex(0.0));
  const int n = reduced.degree();
  if (n == 1) {
    out.emplace_back(-reduced.c_[0] / reduced.c_[1]);
  } else if (n == 2) {
    // Closed form, written to avoid cancellation (Numerical Recipes 5.6).
    const double a = reduced.c_[2], b = reduced.c_[1], c = reduced.c_[0];
    const double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0) {
      const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
      out.emplace_back(q / a);
      out.emplace_back(q != 0.0 ? c / q : 0.0);
    } else {
      const double re = -b / (2.0 * a), im = std::sqrt(-disc) / (2.0 * a);
      out.emplace_back(re, std::abs(im));
      out.emplace_back(re, -std::abs(im));
    }
  } else if (n > 2) {
    Eigen::VectorXd coeffs(n + 1);
    for (int i = 0; i <= n; ++i) coeffs[i] = reduced.c_[static_cast<std::size_t>(i)];
    Eigen::PolynomialSolver<double, Eigen::Dynamic> solver(coeffs);
    std::vector<Complex> raw;
    for (Eigen::Index i = 0; i < solver.roots().size(); ++i) raw.push_back(solver.roots()[i]);
    // Make real roots real and complex roots exact conjugate pairs.
    const double scale = std::max(1.0, std::abs(raw.empty() ? 0.0 : std::abs(raw[0])));
    std::vector<bool> used(raw.size(), false);
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (used[i]) continue;
      used[i] = true;
      const Complex r = raw[i];
      if (std::abs(r.imag()) <= 1e-10 * std::max(scale, std::abs(r))) {
        out.emplace_back(r.real(), 0.0);
        continue;
      }
      std::size_t best = i;
      double best_dist = INFINITY;
      for (std::size_t j = 0; j < raw.size(); ++j) {
        if (used[j]) continue;
        const double d = std::abs(raw[j] - std::conj(r));
        if (d < best_dist) best_dist = d, best = j;
      }
      if (best == i) throw std::runtime_error("polynomial roots: complex root without its conjugate");
      used[best] = true;
      const Complex m = 0.5 * (r + std::conj(raw[best]));
      out.emplace_back(m.real(), std::abs(m.imag()));
      out.emplace_back(m.real(), -std::abs(m.imag()));
    }
  }
  return out;
}

Polynomial operator*(const Polynomial& a, const Polynomial& b) {
  std::vector<double> c(a.c_.size() + b.c_.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.c_.size(); ++i)
    for (std::size_t j = 0; j < b.c_.size(); ++j) c[i + j] += a.c_[i] * b.c_[j];
  return Polynomial(std::move(c));
}

}  // namespace robodamp::filters
