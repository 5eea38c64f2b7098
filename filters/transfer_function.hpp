// Continuous-time rational transfer functions and the blocks of the DVF chain (docs/physics.md §1).
#pragma once

#include <numbers>
#include <string>

#include "filters/polynomial.hpp"
#include "units/units.hpp"

namespace robodamp::filters {

inline double hz_to_rad_per_s(double f_hz) { return kTwoPi * f_hz; }

// H(s) = num(s) / den(s), real coefficients.
class TransferFunction {
 public:
  TransferFunction() : TransferFunction(Polynomial({1.0}), Polynomial({1.0})) {}
  TransferFunction(Polynomial num, Polynomial den);  // throws std::invalid_argument on a zero denominator

  [[nodiscard]] const Polynomial& numerator() const { return num_; }
  [[nodiscard]] const Polynomial& denominator() const { return den_; }
  [[nodiscard]] Complex evaluate(Complex s) const { return num_.evaluate(s) / den_.evaluate(s); }
  [[nodiscard]] Complex at_hz(double f_hz) const { return evaluate(Complex(0.0, hz_to_rad_per_s(f_hz))); }
  [[nodiscard]] bool is_proper() const { return num_.degree() <= den_.degree(); }
  [[nodiscard]] bool all_finite() const { return num_.all_finite() && den_.all_finite(); }

  // Product; common roots at s = 0 are cancelled exactly (integrator x high-pass: 1/s * s^2/D = s/D),
  // which is what keeps a marginally stable integrator off the real-time path.
  friend TransferFunction operator*(const TransferFunction& a, const TransferFunction& b);
  TransferFunction operator*(double k) const;

 private:
  Polynomial num_;
  Polynomial den_;
};

[[nodiscard]] double magnitude_db(Complex h);
[[nodiscard]] double phase_deg(Complex h);  // principal value, (-180, 180]

// --- Blocks of Eq. 8, each from its physical parameters. ---

// Eq. 15: wp^2 / (s^2 + 2 z wp s + wp^2).
TransferFunction lowpass2(double cutoff_hz, double damping_ratio);
// Eq. 13: s^2 / (s^2 + 2 z wh s + wh^2).
TransferFunction highpass2(double cutoff_hz, double damping_ratio);
// Eq. 14: (s^2 + wn^2) / (s^2 + 2 pi a s + wn^2), a = bandwidth in Hz.
TransferFunction notch(double center_hz, double bandwidth_hz);
// 1/s, or the leaky 1/(s + 2 pi f_leak) when leak_hz > 0.
TransferFunction integrator(double leak_hz = 0.0);
// Eq. 3 without its delay: T s^2 / (s^2 + 2 z_a w_a s + w_a^2), newtons per volt.
TransferFunction actuator(double constant_n_per_v, double natural_freq_hz, double damping_ratio);
// Eq. 3 at one frequency with its delay, T s^2 e^(-s delay) / (s^2 + 2 z_a w_a s + w_a^2), newtons per
// volt: the one evaluation the simulated plant, the loop analysis and the actuator's identification use.
[[nodiscard]] inline std::complex<double> actuator_n_per_v(double f_hz, double constant_n_per_v, double natural_freq_hz,
                                                           double damping_ratio, double delay_s) {
  const std::complex<double> s(0.0, kTwoPi * f_hz);
  const double wa = kTwoPi * natural_freq_hz;
  return constant_n_per_v * s * s * std::exp(-s * delay_s) / (s * s + 2.0 * damping_ratio * wa * s + wa * wa);
}
// Eq. 4 with the correction of docs/physics.md: numerator = the actuator denominator; denominator
// s^2 + 2 z_c w_c s + w_c^2 with w_c = 2 pi corner_hz. The paper's -75.44 deg at 9.2 Hz needs z_c = 1.
TransferFunction compensator_c1(double actuator_freq_hz, double actuator_damping_ratio, double corner_hz = 0.5,
                                double corner_damping_ratio = 1.0);
// Eq. 6, pole-zero placement; constant corrected to 211110.1 (printed 2111101).
TransferFunction compensator_c2();
// Eq. 7, pole-zero placement.
TransferFunction compensator_c3();
// Eq. 5, the fitted actuator model that C2 inverts.
TransferFunction actuator_fit_eq5();

}  // namespace robodamp::filters
