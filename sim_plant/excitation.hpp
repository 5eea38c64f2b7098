// Forces on the structure: impact hammer, sine, chirp, white and band-limited noise, and the robot's
// inherent vibration with the drives on. Every source is seeded and reproducible; each returns the mean
// force over a step [t, t + h), which a zero-order hold then applies exactly (an impact's impulse is
// preserved at any step). Constructed off the real-time path; force_n() is RT-safe.
#pragma once

#include <atomic>
#include <complex>
#include <cstdint>
#include <random>
#include <vector>

#include "filters/biquad.hpp"

namespace robodamp::sim {

class Excitation {
 public:
  explicit Excitation(std::size_t location) : location_(location) {}
  virtual ~Excitation() = default;
  // Mean force over [t_s, t_s + h_s), N. Called with consecutive steps.
  virtual double force_n(double t_s, double h_s) noexcept = 0;
  [[nodiscard]] std::size_t location() const { return location_; }

 private:
  std::size_t location_;
};

// Half-sine impacts of a modal hammer: F(t) = peak sin(pi (t - t0) / duration) for t0 <= t < t0 + duration.
class ImpactHammer final : public Excitation {
 public:
  ImpactHammer(std::size_t location, double peak_n, double duration_s, std::vector<double> times_s);
  double force_n(double t_s, double h_s) noexcept override;
  [[nodiscard]] double impulse_n_s() const { return 2.0 * peak_n_ * duration_s_ / M_PI; }
  [[nodiscard]] const std::vector<double>& times_s() const { return times_s_; }

 private:
  double peak_n_, duration_s_;
  std::vector<double> times_s_;
  std::size_t next_{0};
};

class Sine final : public Excitation {
 public:
  Sine(std::size_t location, double amplitude_n, double freq_hz, double phase_rad);
  double force_n(double t_s, double h_s) noexcept override;

 private:
  double amplitude_n_, w_, phase_;
  double end_t_{-1.0}, end_cos_{0.0}, end_sin_{0.0};    // phase at the end of the last step: the next start
  double step_h_s_{0.0}, rot_cos_{1.0}, rot_sin_{0.0};  // rotation of the phase by one step
  int steps_{0};                                        // steps since the phase was evaluated exactly
};

// Linear sine sweep f0 -> f1 over duration_s, then silent (sampled at step mid-points).
class Chirp final : public Excitation {
 public:
  Chirp(std::size_t location, double amplitude_n, double f0_hz, double f1_hz, double duration_s);
  double force_n(double t_s, double h_s) noexcept override;

 private:
  double amplitude_n_, f0_, f1_, duration_s_;
};

// Gaussian white noise of a given RMS per step, optionally band-limited by a Butterworth-type band-pass
// (second-order high-pass and low-pass, digital at the step rate).
class Noise final : public Excitation {
 public:
  Noise(std::size_t location, double rms_n, std::uint64_t seed);
  Noise(std::size_t location, double rms_n, std::uint64_t seed, double band_lo_hz, double band_hi_hz,
        double step_rate_hz);
  double force_n(double t_s, double h_s) noexcept override;

 private:
  double rms_n_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  bool band_limited_{false};
  filters::BiquadCascade band_;
  double band_gain_{1.0};
};

// A force set from outside before each step and held over it (a cut computed step by step against the
// structure's response: milling/damped_dynamics.hpp, hil/regenerative_cut.hpp).
class HeldForce final : public Excitation {
 public:
  explicit HeldForce(std::size_t location) : Excitation(location) {}
  double force_n(double, double) noexcept override { return value_n; }
  double value_n{0.0};
};

// A milling cut's periodic force at the tooth-passing frequency and its harmonics (the HIL emulator's
// cutting forces: the harmonics come from the job, milling::force_spectrum), at a spindle speed that may
// change during the run: F(t) = Re sum_k c_k e^{i k phi(t)}, phi the tooth phase integrated from the speed
// (continuous across changes), k = 0..K (c_0 the mean force). Each step returns the exact mean over the
// step at the speed then. set_tooth_hz() may be called from another thread (atomic); 0 = out of the cut.
class ToothPassingForce final : public Excitation {
 public:
  ToothPassingForce(std::size_t location, std::vector<std::complex<double>> harmonics_n);
  double force_n(double t_s, double h_s) noexcept override;
  void set_tooth_hz(double f_hz) noexcept { tooth_hz_.store(f_hz, std::memory_order_relaxed); }
  [[nodiscard]] double tooth_hz() const noexcept { return tooth_hz_.load(std::memory_order_relaxed); }
  // The tooth phase at the end of the last step, rad (for a lock-in on a response).
  [[nodiscard]] double phase_rad() const noexcept { return phase_; }

 private:
  std::vector<std::complex<double>> c_;
  std::atomic<double> tooth_hz_{0.0};
  double phase_{0.0};
};

}  // namespace robodamp::sim
