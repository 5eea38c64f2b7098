#include "sim_plant/sensor.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace robodamp::sim {

Accelerometer::Accelerometer(const config::SensorConfig& c, double sample_rate_hz, std::uint64_t seed)
    : c_(c), fs_hz_(sample_rate_hz), rng_(seed) {
  if (c.highpass_hz > 0.0) {
    // Bilinear image of s / (s + wc).
    const double k = 2.0 * fs_hz_, wc = kTwoPi * c.highpass_hz;
    hp_gain_ = k / (k + wc);
    hp_pole_ = (k - wc) / (k + wc);
    highpass_ = true;
  }
  // White noise of density n (ug/sqrt(Hz)) sampled at fs: RMS = n sqrt(fs / 2).
  noise_rms_ = c.noise_density_ug_per_rthz * 1e-6 * kStandardGravity * std::sqrt(0.5 * fs_hz_);
  const double mps2_per_v = kStandardGravity / (c.sensitivity_mv_per_g * 1e-3);
  lsb_mps2_ = 2.0 * c.adc_range_v / std::ldexp(1.0, c.adc_bits) * mps2_per_v;
  range_mps2_ = c.range_g * kStandardGravity;
  adc_full_scale_mps2_ = c.adc_range_v * mps2_per_v;
}

double Accelerometer::measure(double a) noexcept {
  if (!std::isfinite(a)) return a;  // a non-finite plant is the caller's fault to see, not to hide
  double y = a;
  if (highpass_) {
    y = hp_gain_ * (a - x1_) + hp_pole_ * y1_;
    x1_ = a;
    y1_ = y;
  }
  if (noise_rms_ > 0.0) y += noise_rms_ * normal_(rng_);  // (a noiseless sensor draws nothing: same output)
  const double limit = std::min(range_mps2_, adc_full_scale_mps2_);
  if (std::abs(y) > limit) {
    y = std::copysign(limit, y);
    ++clipped_;
  }
  // std::round (half away from zero) without the libm call: |counts| < 2^31 after the clip above, so the
  // truncation is exact and so is counts - whole.
  const double counts = y / lsb_mps2_;
  const auto whole = static_cast<double>(static_cast<std::int64_t>(counts));
  const double frac = counts - whole;
  return (whole + static_cast<double>(frac >= 0.5) - static_cast<double>(frac <= -0.5)) * lsb_mps2_;
}

std::complex<double> Accelerometer::response(double f_hz) const {
  if (!highpass_) return 1.0;
  const std::complex<double> zi = std::exp(std::complex<double>(0.0, -kTwoPi * f_hz / fs_hz_));
  return hp_gain_ * (1.0 - zi) / (1.0 - hp_pole_ * zi);
}

std::complex<double> Accelerometer::analog_response(double f_hz) const {
  if (!highpass_) return 1.0;
  const std::complex<double> s(0.0, kTwoPi * f_hz);
  return s / (s + kTwoPi * c_.highpass_hz);
}

}  // namespace robodamp::sim
