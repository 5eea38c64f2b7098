// Actuator identification (docs/identification.md, "Actuator"): Eq. 3's force constant T, natural
// frequency, damping ratio and pure delay,
//   F/V = T s^2 / (s^2 + 2 zeta wa s + wa^2) e^{-s tau},
// fitted to a measured force-per-volt FRF. The FRF comes either from the transmitted force directly or,
// with an accelerometer on the structure, from the acceleration per volt divided by the structure's
// accelerance at the actuator (and the sensor's coupling and the loop's sample-and-hold). For each
// delay on a grid (then refined by golden section) the rest is linear least squares,
//   G (s^2 + a1 s + a0) = T s^2 e^{-s tau},
// weighted to relative error; the delay with the smallest relative error wins. Deterministic.
#pragma once

#include <complex>
#include <functional>
#include <vector>

#include "analysis/spectral.hpp"
#include "filters/transfer_function.hpp"

namespace robodamp::identify {

using Complex = std::complex<double>;

struct ActuatorFrf {
  std::vector<double> f_hz;
  std::vector<Complex> n_per_v;
  std::vector<double> coherence;  // empty: all 1
};

struct ActuatorFitSettings {
  double band_lo_hz{5.0}, band_hi_hz{100.0};
  double min_coherence{0.9};
  double max_delay_ms{5.0};
};

struct ActuatorFit {
  double force_constant_n_per_v{0.0};
  double natural_freq_hz{0.0};
  double damping_ratio{0.0};
  double delay_ms{0.0};
  double fit_error_pct{0.0};  // RMS |G - G_fit| / RMS |G| over the points used, %
  double band_lo_hz{0.0}, band_hi_hz{0.0};
  int points{0};
  std::vector<double> f_hz;  // the points used
  std::vector<Complex> measured, fitted;
};

// Throws std::invalid_argument: too few coherent points in the band, non-finite data, or no physical
// (positive stiffness and damping) fit.
[[nodiscard]] ActuatorFit fit_actuator(const ActuatorFrf& frf, const ActuatorFitSettings& s);

// Periodic excitation: the H1 FRF (output per input) and coherence over whole periods of period_n
// samples starting at `first` (rectangular window: a periodic steady state has no leakage).
[[nodiscard]] analysis::FrfEstimate periodic_frf(const std::vector<double>& input, const std::vector<double>& output,
                                                 std::size_t first, std::size_t period_n, int periods, double fs_hz,
                                                 double max_hz);

// Force per volt from acceleration per volt measured through the loop: divided by the structure's
// accelerance at the sensor for a force at the actuator (-w^2 x receptance), the sensor's sampled
// coupling and the loop's output path (the command written at tick k is held over [k+1, k+2): 1.5
// periods of delay and the hold's sinc at the sample period T).
[[nodiscard]] ActuatorFrf force_per_volt_from_acceleration(const analysis::FrfEstimate& accel_per_volt,
                                                           const std::function<Complex(double)>& structure_receptance,
                                                           const std::function<Complex(double)>& sensor_response,
                                                           double sample_period_s);

}  // namespace robodamp::identify
