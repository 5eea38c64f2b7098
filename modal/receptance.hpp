// The robot's structure as modal data (Eq. 1, residue or modal-stiffness form):
// each mode's numerator, the receptance of an FRF path, the dominant mode. The physics the configuration's
// robot section describes; used by the chain design (the compensator's pre-warp), the simulated plant and
// the milling structures.
#pragma once

#include <complex>
#include <optional>

#include "config/config.hpp"

namespace robodamp::modal {

// Eq. 1 numerator of one mode, H(s) = (a + b s) / (s^2 + 2 zeta wn s + wn^2), in the tabulated frame:
// residue form a = 2 (zeta wn re - wd im), b = 2 re; stiffness form a = wn^2 / k, b = 0.
struct ModeNumerator {
  double a{0.0};  // m/N * rad^2/s^2
  double b{0.0};  // m/N * rad/s
};
[[nodiscard]] ModeNumerator mode_numerator(const config::ModeConfig& m);
// Eq. 1, one mode's receptance at s from its numerator: (a + b s) / (s^2 + 2 zeta wn s + wn^2), m/N. The
// one evaluation of a mode: the FRF paths here and the simulated plant's use it.
[[nodiscard]] inline std::complex<double> mode_receptance(double a, double b, double zeta, double wn_rad_per_s,
                                                          std::complex<double> s) {
  return (a + b * s) / (s * s + 2.0 * zeta * wn_rad_per_s * s + wn_rad_per_s * wn_rad_per_s);
}
// Receptance of one FRF path at f_hz, tabulated frame (no axis sign), m/N.
[[nodiscard]] std::complex<double> frf_receptance(const config::FrfConfig& f, double f_hz);

// Frequency of the robot mode with the largest receptance peak, preferring the driving-point FRF at the
// actuator location where the loop closes; nullopt without modal data.
[[nodiscard]] std::optional<double> dominant_mode_hz(const config::RobotConfig& robot, int actuator_location = 2);

}  // namespace robodamp::modal
