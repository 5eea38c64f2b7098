// Spindle-locked harmonic notches (docs/harmonic_notch.md): notches at the tooth-passing frequency and
// its first H harmonics that follow the spindle, as PX4's and ArduPilot's dynamic harmonic notches follow
// the motors. Each notch is the bilinear map (pre-warped at its centre) of
//   N(s) = (s^2 + 2 zeta_z w0 s + w0^2) / (s^2 + 2 zeta_p w0 s + w0^2),
//   zeta_p = bandwidth / (2 f0),  zeta_z = zeta_p 10^(-depth_db / 20),
// which attenuates by exactly depth_db at f0 and has the given -3 dB width there (for deep notches).
//
// The centres are recomputed at update_hz (not every sample): the target follows the tooth frequency, the
// centre moves towards it by at most slew_fraction of itself per update. While the bank is faded out
// (spindle stopped, speed unknown or below min_hz) the centre jumps; then the bank fades in over fade_s.
// Harmonics at or above max_fraction_of_fs x fs fade out on their own. Each notch is mixed in with its
// fade g as x + g (N x - x) = ((1 - g) A + g B) / A for N = B / A: one biquad whose numerator blends
// towards the denominator, so the mix costs nothing per sample. A notch's state stays across every
// coefficient change (transposed direct form II): starting, stopping and moving never switch the signal
// path abruptly. A notch whose fade reaches 0 leaves the path (its state cleared), so a parked bank passes
// the signal bit for bit. Everything after construction is RT-safe: no allocation, locking, exceptions.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>

#include "filters/biquad.hpp"
#include "units/units.hpp"

namespace robodamp::filters {

inline constexpr int kMaxHarmonics = 8;

struct HarmonicNotchSettings {
  bool enabled{false};
  int harmonics{3};            // notches at 1..harmonics x the tooth frequency
  double bandwidth_hz{10.0};   // -3 dB width of each notch
  double depth_db{30.0};       // attenuation at each centre
  double slew_fraction{0.05};  // largest centre move per update, relative to the centre
  double min_hz{10.0};         // below it (or an unknown speed) the bank parks and fades out
  double fade_s{0.2};
  double update_hz{100.0};
  double max_fraction_of_fs{0.45};  // harmonics at or above this fraction of the sample rate are off
};

struct HarmonicNotchCounters {
  std::uint64_t updates{0};
  std::uint64_t slew_limited{0};    // updates whose centre move was limited
  std::uint64_t parked{0};          // updates spent parked (no valid tooth frequency)
  std::uint64_t invalid_inputs{0};  // tooth frequencies refused (NaN, negative, infinite)
};

class HarmonicNotchBank final {
 public:
  HarmonicNotchBank() = default;
  HarmonicNotchBank(const HarmonicNotchSettings& s, double fs_hz) noexcept { configure(s, fs_hz); }

  // RT-safe. New settings; the notches' states and the centre carry over.
  void configure(const HarmonicNotchSettings& s, double fs_hz) noexcept {
    s_ = s;
    s_.harmonics = std::clamp(s_.harmonics, 1, kMaxHarmonics);
    fs_hz_ = fs_hz;
    update_every_ =
        std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::lround(fs_hz / std::max(s_.update_hz, 1e-3))));
    const double update_s = update_every_ / fs_hz;
    fade_step_ = s_.fade_s > 0.0 ? update_s / s_.fade_s : 1.0;
    depth_ratio_ = std::pow(10.0, -s_.depth_db / 20.0);
    top_tan_ = std::tan(M_PI * s_.max_fraction_of_fs);
    if (centre_hz_ <= 0.0) centre_hz_ = std::max(s_.min_hz, 1e-3);
    design_all();
    index_active();
  }

  // RT-safe. The tooth-passing frequency to follow (spindle speed x teeth / 60), Hz; 0 = spindle
  // stopped. NaN, negative or infinite values are counted and park the bank.
  void set_tooth_frequency(double f_hz) noexcept {
    if (!std::isfinite(f_hz) || f_hz < 0.0) {
      ++counters_.invalid_inputs;
      f_hz = 0.0;
    }
    target_hz_ = f_hz;
  }

  // RT-safe. Steady state for a constant input (every notch passes DC unchanged).
  void reset(double x) noexcept {
    if (!std::isfinite(x)) x = 0.0;
    for (int k = 0; k < kMaxHarmonics; ++k) {
      const auto& c = mixed_[static_cast<std::size_t>(k)];
      auto& st = state_[static_cast<std::size_t>(k)];
      st.s2 = (c.b2 - c.a2) * x;
      st.s1 = (c.b1 - c.a1) * x + st.s2;
    }
  }

  // RT-safe. One sample through the bank.
  [[nodiscard]] double process(double x) noexcept {
    if (!s_.enabled) return x;
    if (++since_update_ >= update_every_) {
      since_update_ = 0;
      update();
    }
    double v = x;
    const std::size_t n = active_count_;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = active_[i];
      v = BiquadCascade::step(mixed_[k], state_[k], v);
    }
    if (!std::isfinite(v)) [[unlikely]] {  // overflow: clear the notches' state, pass the input
      for (auto& st : state_) st = {};
      return x;
    }
    return v;
  }

  // Off the real-time path (or for reports): the bank's response at f with its current centre and fades.
  [[nodiscard]] std::complex<double> response(double f_hz) const {
    if (!s_.enabled) return 1.0;
    const std::complex<double> z1 = std::polar(1.0, -kTwoPi * f_hz / fs_hz_);
    std::complex<double> h = 1.0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(s_.harmonics); ++k) {
      if (gain_[k] == 0.0) continue;
      const auto& c = mixed_[k];
      h *= (c.b0 + c.b1 * z1 + c.b2 * z1 * z1) / (1.0 + c.a1 * z1 + c.a2 * z1 * z1);
    }
    return h;
  }

  // One notch's coefficients (pre-warped bilinear of N(s) above).
  [[nodiscard]] static BiquadCoefficients design(double centre_hz, double bandwidth_hz, double depth_db,
                                                 double fs_hz) noexcept {
    return design_warped(std::tan(M_PI * centre_hz / fs_hz), centre_hz, bandwidth_hz, std::pow(10.0, -depth_db / 20.0));
  }
  // The same from the pre-warped centre w = tan(pi centre / fs) and the depth as a ratio.
  [[nodiscard]] static BiquadCoefficients design_warped(double w, double centre_hz, double bandwidth_hz,
                                                        double depth_ratio) noexcept {
    const double zp = bandwidth_hz / (2.0 * centre_hz), zz = zp * depth_ratio;
    const double a0 = 1.0 + 2.0 * zp * w + w * w;
    BiquadCoefficients c;
    c.b0 = (1.0 + 2.0 * zz * w + w * w) / a0;
    c.b1 = 2.0 * (w * w - 1.0) / a0;
    c.b2 = (1.0 - 2.0 * zz * w + w * w) / a0;
    c.a1 = c.b1;
    c.a2 = (1.0 - 2.0 * zp * w + w * w) / a0;
    return c;
  }

  [[nodiscard]] double centre_hz() const noexcept { return centre_hz_; }
  [[nodiscard]] double target_hz() const noexcept { return target_hz_; }
  [[nodiscard]] double fade() const noexcept { return fade_; }
  [[nodiscard]] double harmonic_gain(int k) const noexcept { return gain_[static_cast<std::size_t>(k)]; }
  [[nodiscard]] bool harmonic_on(int k) const noexcept { return harmonic_on(s_, centre_hz_, k, fs_hz_); }

  // The one rule of which notches are in the path (the bank's and the loop analysis', analysis/loop_model):
  // harmonic k (0 = the tooth frequency) is on when the bank is valid (tooth frequency at least min_hz) and
  // (k + 1) x the tooth frequency is below max_fraction_of_fs x fs.
  [[nodiscard]] static bool harmonic_on(const HarmonicNotchSettings& s, double tooth_hz, int k, double fs_hz) noexcept {
    return (k + 1) * tooth_hz < s.max_fraction_of_fs * fs_hz;
  }
  // How many notches a bank with these settings runs at a steady tooth frequency, fully faded in.
  [[nodiscard]] static int steady_count(const HarmonicNotchSettings& s, double tooth_hz, double fs_hz) noexcept {
    if (!s.enabled || !(tooth_hz >= s.min_hz)) return 0;
    const int harmonics = std::clamp(s.harmonics, 1, kMaxHarmonics);
    int n = 0;
    while (n < harmonics && harmonic_on(s, tooth_hz, n, fs_hz)) ++n;
    return n;
  }
  [[nodiscard]] const HarmonicNotchSettings& settings() const noexcept { return s_; }
  [[nodiscard]] const HarmonicNotchCounters& counters() const noexcept { return counters_; }

 private:
  void update() noexcept {
    ++counters_.updates;
    const bool valid = target_hz_ >= s_.min_hz;
    if (!valid) {
      ++counters_.parked;
      fade_ = std::max(0.0, fade_ - fade_step_);
    } else if (fade_ <= 0.0) {
      centre_hz_ = target_hz_;  // out of the signal path: jump, then fade in
      fade_ = fade_step_;
    } else {
      const double max_move = s_.slew_fraction * centre_hz_, move = target_hz_ - centre_hz_;
      if (std::abs(move) > max_move) {
        centre_hz_ += std::copysign(max_move, move);
        ++counters_.slew_limited;
      } else {
        centre_hz_ = target_hz_;
      }
      fade_ = std::min(1.0, fade_ + fade_step_);
    }
    bool changed = centre_hz_ != designed_hz_;
    for (int k = 0; k < s_.harmonics; ++k) {
      const double target = harmonic_on(k) ? 1.0 : 0.0;  // each harmonic fades at the same rate
      const double own = own_[static_cast<std::size_t>(k)];
      own_[static_cast<std::size_t>(k)] =
          target > own ? std::min(target, own + fade_step_) : std::max(target, own - fade_step_);
      const double g = fade_ * own_[static_cast<std::size_t>(k)];
      changed = changed || g != gain_[static_cast<std::size_t>(k)];
      gain_[static_cast<std::size_t>(k)] = g;
      if (gain_[static_cast<std::size_t>(k)] == 0.0) state_[static_cast<std::size_t>(k)] = {};  // out of the path
    }
    if (!changed) return;  // steady: centre, fades and coefficients as they are
    design_all();
    index_active();
  }

  // The notches in the signal path (gain above 0), in order: what process() runs.
  void index_active() noexcept {
    active_count_ = 0;
    for (int k = 0; k < s_.harmonics; ++k)
      if (gain_[static_cast<std::size_t>(k)] != 0.0) active_[active_count_++] = static_cast<std::uint8_t>(k);
  }

  // Every notch's coefficients, blended with its fade. The harmonics' pre-warped centres come from the
  // fundamental's by the tangent addition formula, tan((k+1) t) = (tan k t + tan t) / (1 - tan k t tan t)
  // (exact to rounding below 0.45 fs, where tan stays below 6.4): one tangent per update, not one per notch.
  void design_all() noexcept {
    designed_hz_ = centre_hz_;
    const double top = s_.max_fraction_of_fs * fs_hz_;
    const double t1 = std::tan(M_PI * centre_hz_ / fs_hz_);
    double tk = t1;
    for (int k = 0; k < s_.harmonics; ++k) {
      if (k > 0) tk = (tk + t1) / (1.0 - tk * t1);
      double f = (k + 1) * centre_hz_, w = tk;
      if (f >= top) f = top, w = top_tan_;  // an off harmonic keeps running at the limit
      const BiquadCoefficients n = design_warped(w, f, std::min(s_.bandwidth_hz, f), depth_ratio_);
      const double g = gain_[static_cast<std::size_t>(k)];
      BiquadCoefficients& m = mixed_[static_cast<std::size_t>(k)];
      m = n;  // (1 - g) A + g B over A (A's leading coefficient is 1)
      m.b0 = (1.0 - g) + g * n.b0;
      m.b1 = (1.0 - g) * n.a1 + g * n.b1;
      m.b2 = (1.0 - g) * n.a2 + g * n.b2;
    }
  }

  HarmonicNotchSettings s_{};
  double fs_hz_{5000.0};
  std::uint32_t update_every_{50}, since_update_{0};
  double fade_step_{0.05};
  double depth_ratio_{1.0}, top_tan_{1.0};
  double designed_hz_{-1.0};  // the centre the coefficients were designed for
  double target_hz_{0.0}, centre_hz_{0.0}, fade_{0.0};
  std::array<BiquadCoefficients, kMaxHarmonics> mixed_{};  // each notch blended with its fade
  std::array<BiquadCascade::State, kMaxHarmonics> state_{};
  std::array<double, kMaxHarmonics> own_{}, gain_{};
  std::array<std::uint8_t, kMaxHarmonics> active_{};
  std::size_t active_count_{0};
  HarmonicNotchCounters counters_{};
};

}  // namespace robodamp::filters
