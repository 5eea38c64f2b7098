#include "filters/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robodamp::filters {

TransferFunction::TransferFunction(Polynomial num, Polynomial den) : num_(std::move(num)), den_(std::move(den)) {
  if (den_.is_zero()) throw std::invalid_argument("transfer function: zero denominator");
}

TransferFunction operator*(const TransferFunction& a, const TransferFunction& b) {
  Polynomial num = a.num_ * b.num_;
  Polynomial den = a.den_ * b.den_;
  const int common = std::min(num.roots_at_zero(), den.roots_at_zero());
  if (common > 0 && !num.is_zero()) {
    num = num.drop_roots_at_zero(common);
    den = den.drop_roots_at_zero(common);
  }
  return {std::move(num), std::move(den)};
}

TransferFunction TransferFunction::operator*(double k) const {
  return *this * TransferFunction(Polynomial({k}), Polynomial({1.0}));
}

double magnitude_db(Complex h) { return 20.0 * std::log10(std::abs(h)); }
double phase_deg(Complex h) { return std::arg(h) * 180.0 / std::numbers::pi; }

namespace {
// s^2 + 2 z w s + w^2 (ascending coefficients).
Polynomial second_order(double w_rad_s, double damping_ratio) {
  return Polynomial({w_rad_s * w_rad_s, 2.0 * damping_ratio * w_rad_s, 1.0});
}
}  // namespace

TransferFunction lowpass2(double cutoff_hz, double damping_ratio) {
  const double w = hz_to_rad_per_s(cutoff_hz);
  return {Polynomial({w * w}), second_order(w, damping_ratio)};
}

TransferFunction highpass2(double cutoff_hz, double damping_ratio) {
  return {Polynomial({0.0, 0.0, 1.0}), second_order(hz_to_rad_per_s(cutoff_hz), damping_ratio)};
}

TransferFunction notch(double center_hz, double bandwidth_hz) {
  const double w = hz_to_rad_per_s(center_hz);
  return {Polynomial({w * w, 0.0, 1.0}), Polynomial({w * w, hz_to_rad_per_s(bandwidth_hz), 1.0})};
}

TransferFunction integrator(double leak_hz) { return {Polynomial({1.0}), Polynomial({hz_to_rad_per_s(leak_hz), 1.0})}; }

TransferFunction actuator(double constant_n_per_v, double natural_freq_hz, double damping_ratio) {
  return {Polynomial({0.0, 0.0, constant_n_per_v}), second_order(hz_to_rad_per_s(natural_freq_hz), damping_ratio)};
}

TransferFunction compensator_c1(double actuator_freq_hz, double actuator_damping_ratio, double corner_hz,
                                double corner_damping_ratio) {
  return {second_order(hz_to_rad_per_s(actuator_freq_hz), actuator_damping_ratio),
          second_order(hz_to_rad_per_s(corner_hz), corner_damping_ratio)};
}

TransferFunction compensator_c2() {
  return {Polynomial::from_descending({3.0, 413.7, 17241.0, 211110.1}),
          Polynomial::from_descending({1.004, 1254.0, 98360.0, 186300.0})};
}

TransferFunction compensator_c3() {
  return {Polynomial::from_descending({0.7555, 27.18, 3082.0}), Polynomial::from_descending({1.0, 130.6, 21600.0})};
}

TransferFunction actuator_fit_eq5() {
  return {Polynomial::from_descending({1.612, 1278.0, 7.733e4, 1.453e5}),
          Polynomial::from_descending({1.0, 174.6, 8221.0, 5.491e4})};
}

}  // namespace robodamp::filters
