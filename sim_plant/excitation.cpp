#include "sim_plant/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "filters/design.hpp"
#include "filters/transfer_function.hpp"
#include "units/units.hpp"

namespace robodamp::sim {

ImpactHammer::ImpactHammer(std::size_t location, double peak_n, double duration_s, std::vector<double> times_s)
    : Excitation(location), peak_n_(peak_n), duration_s_(duration_s), times_s_(std::move(times_s)) {
  if (!(duration_s_ > 0.0)) throw std::invalid_argument("impact duration must be > 0 s");
  std::sort(times_s_.begin(), times_s_.end());
}

double ImpactHammer::force_n(double t_s, double h_s) noexcept {
  while (next_ < times_s_.size() && times_s_[next_] + duration_s_ <= t_s) ++next_;
  double impulse = 0.0;
  for (std::size_t i = next_; i < times_s_.size() && times_s_[i] < t_s + h_s; ++i) {
    // Exact integral of the half-sine over the overlap of [t, t + h) and the pulse.
    const double lo = std::max(t_s, times_s_[i]) - times_s_[i];
    const double hi = std::min(t_s + h_s, times_s_[i] + duration_s_) - times_s_[i];
    if (hi > lo)
      impulse += peak_n_ * duration_s_ / M_PI * (std::cos(M_PI * lo / duration_s_) - std::cos(M_PI * hi / duration_s_));
  }
  return impulse / h_s;
}

Sine::Sine(std::size_t location, double amplitude_n, double freq_hz, double phase_rad)
    : Excitation(location), amplitude_n_(amplitude_n), w_(kTwoPi * freq_hz), phase_(phase_rad) {}

double Sine::force_n(double t_s, double h_s) noexcept {
  // Mean of A sin(w t + phi) over the step: A (cos(w t0 + phi) - cos(w t1 + phi)) / (w h). Consecutive steps of
  // one length rotate (cos, sin) of the phase by w h (four products instead of a cos per step); the phase
  // is evaluated exactly at the first step, after a jump in time and every kExactEvery steps, so rounding
  // cannot accumulate (it stays near 1e-13 of the amplitude).
  constexpr int kExactEvery = 1024;
  const bool consecutive = h_s == step_h_s_ && std::abs(t_s - end_t_) <= 1e-12 * (1.0 + t_s) && steps_ < kExactEvery;
  double c0, s0;
  if (consecutive) {
    c0 = end_cos_, s0 = end_sin_;
    ++steps_;
  } else {
    c0 = std::cos(w_ * t_s + phase_), s0 = std::sin(w_ * t_s + phase_);
    if (h_s != step_h_s_) step_h_s_ = h_s, rot_cos_ = std::cos(w_ * h_s), rot_sin_ = std::sin(w_ * h_s);
    steps_ = 0;
  }
  end_t_ = t_s + h_s;
  end_cos_ = c0 * rot_cos_ - s0 * rot_sin_;
  end_sin_ = s0 * rot_cos_ + c0 * rot_sin_;
  return amplitude_n_ * (c0 - end_cos_) / (w_ * h_s);
}

Chirp::Chirp(std::size_t location, double amplitude_n, double f0_hz, double f1_hz, double duration_s)
    : Excitation(location), amplitude_n_(amplitude_n), f0_(f0_hz), f1_(f1_hz), duration_s_(duration_s) {}

double Chirp::force_n(double t_s, double h_s) noexcept {
  const double t = t_s + 0.5 * h_s;
  if (t >= duration_s_) return 0.0;
  const double k = (f1_ - f0_) / duration_s_;
  return amplitude_n_ * std::sin(kTwoPi * (f0_ * t + 0.5 * k * t * t));
}

Noise::Noise(std::size_t location, double rms_n, std::uint64_t seed)
    : Excitation(location), rms_n_(rms_n), rng_(seed) {}

Noise::Noise(std::size_t location, double rms_n, std::uint64_t seed, double band_lo_hz, double band_hi_hz,
             double step_rate_hz)
    : Noise(location, rms_n, seed) {
  const auto tf = filters::highpass2(band_lo_hz, M_SQRT1_2) * filters::lowpass2(band_hi_hz, M_SQRT1_2);
  const auto d = filters::bilinear_sos(tf, step_rate_hz, std::sqrt(band_lo_hz * band_hi_hz));
  band_ = filters::BiquadCascade(filters::SosCoefficients::from(d.sections));
  // Scale so the output RMS is rms_n: the mean of |H|^2 over (0, Nyquist) for unit-variance white input.
  double power = 0.0;
  const int n = 8192;
  for (int i = 0; i < n; ++i)
    power +=
        std::norm(filters::digital_response(d.sections, 1.0, (i + 0.5) / n * 0.5 * step_rate_hz, step_rate_hz)) / n;
  band_gain_ = 1.0 / std::sqrt(std::max(power, 1e-300));
  band_limited_ = true;
}

double Noise::force_n(double, double) noexcept {
  const double w = normal_(rng_);
  if (!band_limited_) return rms_n_ * w;
  return rms_n_ * band_gain_ * band_.process(w);
}

ToothPassingForce::ToothPassingForce(std::size_t location, std::vector<std::complex<double>> harmonics_n)
    : Excitation(location), c_(std::move(harmonics_n)) {}

double ToothPassingForce::force_n(double /*t_s*/, double h_s) noexcept {
  const double f = tooth_hz();
  if (!(f > 0.0) || c_.empty()) return 0.0;
  const double dphi = kTwoPi * f * h_s;  // over the step
  double sum = c_[0].real();
  for (std::size_t k = 1; k < c_.size(); ++k) {
    // Mean of e^{i k phi} over [phi0, phi0 + dphi]: e^{i k phi0} (e^{i k dphi} - 1) / (i k dphi).
    const double kd = static_cast<double>(k) * dphi;
    const std::complex<double> start = std::polar(1.0, static_cast<double>(k) * phase_);
    const std::complex<double> mean = kd > 1e-9 ? (std::polar(1.0, kd) - 1.0) / std::complex<double>(0.0, kd) : 1.0;
    sum += (c_[k] * start * mean).real();
  }
  phase_ = std::fmod(phase_ + dphi, kTwoPi);
  return sum;
}

}  // namespace robodamp::sim
