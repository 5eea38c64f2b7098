#include "modal/receptance.hpp"
#include "units/units.hpp"

#include <cmath>

namespace robodamp::modal {

ModeNumerator mode_numerator(const config::ModeConfig& m) {
  const double wn = kTwoPi * m.natural_freq_hz;
  if (m.form == config::ModeForm::kStiffness) return {wn * wn / m.stiffness_n_per_m, 0.0};
  const double wd = wn * std::sqrt(1.0 - m.damping_ratio * m.damping_ratio);
  return {2.0 * (m.damping_ratio * wn * m.residue_re_m_per_n - wd * m.residue_im_m_per_n), 2.0 * m.residue_re_m_per_n};
}

std::complex<double> frf_receptance(const config::FrfConfig& f, double f_hz) {
  const std::complex<double> s(0.0, kTwoPi * f_hz);
  std::complex<double> h(0.0);
  for (const auto& m : f.modes) {
    const double wn = kTwoPi * m.natural_freq_hz;
    const ModeNumerator n = mode_numerator(m);
    h += mode_receptance(n.a, n.b, m.damping_ratio, wn, s);
  }
  return h;
}

std::optional<double> dominant_mode_hz(const config::RobotConfig& robot, int actuator_location) {
  const config::FrfConfig* best_frf = nullptr;
  for (const auto& f : robot.frfs)
    if (f.response_location == actuator_location && f.excitation_location == actuator_location) best_frf = &f;
  std::optional<double> best_hz;
  double best_peak = -1.0;
  for (const auto& f : robot.frfs) {
    if (best_frf != nullptr && &f != best_frf) continue;
    // |H| of the whole FRF at each mode's frequency, so close modes count together.
    for (const auto& probe : f.modes)
      if (const double h = std::abs(frf_receptance(f, probe.natural_freq_hz)); h > best_peak)
        best_peak = h, best_hz = probe.natural_freq_hz;
  }
  return best_hz;
}

}  // namespace robodamp::modal
