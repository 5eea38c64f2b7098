// The accelerometer and its ADC channel: IEPE coupling high-pass (first order, bilinear at the sample
// rate), white noise of a given density, the sensor's range, and ADC clipping and quantisation.
// Constructed off the real-time path; measure() is RT-safe.
#pragma once

#include <complex>
#include <cstdint>
#include <random>

#include "config/config.hpp"

namespace robodamp::sim {

class Accelerometer {
 public:
  Accelerometer(const config::SensorConfig& c, double sample_rate_hz, std::uint64_t seed);

  // True acceleration at the sample instant (m/s^2) -> the reading after coupling, noise, range and
  // quantisation, converted back with the nominal sensitivity (m/s^2).
  [[nodiscard]] double measure(double true_mps2) noexcept;
  void reset() noexcept { x1_ = y1_ = 0.0; }

  // Linear part as sampled (what the discrete loop analysis uses) and its analog model.
  [[nodiscard]] std::complex<double> response(double f_hz) const;
  [[nodiscard]] std::complex<double> analog_response(double f_hz) const;

  // First-order coupling as realised: y[k] = gain (x[k] - x[k-1]) + pole y[k-1]; none = pass-through.
  [[nodiscard]] bool has_highpass() const { return highpass_; }
  [[nodiscard]] double highpass_gain() const { return hp_gain_; }
  [[nodiscard]] double highpass_pole() const { return hp_pole_; }
  [[nodiscard]] double noise_rms_mps2() const { return noise_rms_; }
  [[nodiscard]] double lsb_mps2() const { return lsb_mps2_; }
  [[nodiscard]] double range_mps2() const { return range_mps2_; }
  [[nodiscard]] std::uint64_t clipped_count() const { return clipped_; }
  [[nodiscard]] const config::SensorConfig& config() const { return c_; }

 private:
  config::SensorConfig c_;
  double fs_hz_;
  double hp_gain_{1.0}, hp_pole_{0.0};  // y = g (x - x1) + p y1
  bool highpass_{false};
  double x1_{0.0}, y1_{0.0};
  double noise_rms_{0.0};
  double lsb_mps2_{0.0};
  double range_mps2_{0.0};
  double adc_full_scale_mps2_{0.0};
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::uint64_t clipped_{0};
};

inline constexpr double kStandardGravity = 9.80665;  // m/s^2 per g

}  // namespace robodamp::sim
