// The real-time filter: a cascade of biquads in transposed direct form II (double precision).
// Coefficients live apart from state (as in iir1), so a new set designed off the real-time thread can be
// swapped in at a sample boundary while the signal history stays.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace robodamp::filters {

// H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2).
struct BiquadCoefficients {
  double b0{1.0}, b1{0.0}, b2{0.0}, a1{0.0}, a2{0.0};
};

inline constexpr std::size_t kMaxSections = 16;

// Fixed-capacity coefficient set: copyable on the real-time thread without allocation.
struct SosCoefficients {
  std::array<BiquadCoefficients, kMaxSections> sections{};
  std::size_t count{0};

  // Off the real-time path.
  static SosCoefficients from(const std::vector<BiquadCoefficients>& v) {
    if (v.size() > kMaxSections)
      throw std::length_error("filter needs " + std::to_string(v.size()) + " second-order sections, at most " +
                              std::to_string(kMaxSections) + " are supported");
    SosCoefficients c;
    for (std::size_t i = 0; i < v.size(); ++i) c.sections[i] = v[i];
    c.count = v.size();
    return c;
  }
};

class BiquadCascade final {
 public:
  BiquadCascade() = default;
  explicit BiquadCascade(const SosCoefficients& c) : c_(c) {}

  // RT-safe. A non-finite input never enters the state: it is counted and the last output is held.
  // A non-finite result (overflow) clears the state, is counted, and gives 0.
  [[nodiscard]] double process(double x) noexcept {
    if (!std::isfinite(x)) {
      ++nonfinite_inputs_;
      return last_output_;
    }
    if (record_left_ != 0) [[unlikely]]
      return finish(process_recording(x));
    double v = x;
    for (std::size_t i = 0; i < c_.count; ++i) {
      v = step(c_.sections[i], state_[i], v);
    }
    return finish(v);
  }

  // RT-safe. Steady state for a constant input x (PX4's reset(sample)): the next output for input x
  // equals the DC response, with no transient.
  void reset(double x) noexcept {
    if (!std::isfinite(x)) x = 0.0;
    double v = x;
    for (std::size_t i = 0; i < c_.count; ++i) {
      const BiquadCoefficients& k = c_.sections[i];
      const double den = 1.0 + k.a1 + k.a2;
      const double y = den != 0.0 ? v * (k.b0 + k.b1 + k.b2) / den : 0.0;
      state_[i].s2 = k.b2 * v - k.a2 * y;
      state_[i].s1 = k.b1 * v - k.a1 * y + state_[i].s2;
      boundary_[0][i] = boundary_[1][i] = v;
      v = y;
    }
    boundary_[0][c_.count] = boundary_[1][c_.count] = v;
    for (std::size_t i = c_.count; i < kMaxSections; ++i) state_[i] = {};
    last_output_ = v;
  }

  // RT-safe. Requests new coefficients; they take over at the sample boundary after the next two
  // processed samples (whose section-boundary signals are recorded for it). The new coefficients
  // take over the actual signal history at every section boundary (the direct-form-I view of the
  // state), so the output continues from where it was and moves to the new response with the new
  // filter's own dynamics. Sections beyond the old count see the old cascade's output, as if the
  // missing old sections were identity. Recording only around a swap keeps the per-sample cost of
  // the normal path at that of a plain cascade plus the NaN guard.
  void request_swap(const SosCoefficients& next) noexcept {
    next_ = next;
    swap_pending_ = true;
    record_left_ = 2;
  }
  [[nodiscard]] bool swap_pending() const noexcept { return swap_pending_; }

  [[nodiscard]] const SosCoefficients& coefficients() const noexcept { return c_; }
  [[nodiscard]] std::uint64_t nonfinite_input_count() const noexcept { return nonfinite_inputs_; }
  [[nodiscard]] std::uint64_t state_reset_count() const noexcept { return state_resets_; }
  [[nodiscard]] double last_output() const noexcept { return last_output_; }

  // One section's state and step (also used by filters/harmonic_notch.hpp).
  struct State {
    double s1{0.0}, s2{0.0};
  };

  // One TDF-II section: y = b0 x + s1; s1' = b1 x - a1 y + s2; s2' = b2 x - a2 y.
  static double step(const BiquadCoefficients& k, State& s, double x) noexcept {
    const double y = k.b0 * x + s.s1;
    s.s1 = k.b1 * x - k.a1 * y + s.s2;
    s.s2 = k.b2 * x - k.a2 * y;
    return y;
  }

 private:
  double finish(double v) noexcept {
    if (!std::isfinite(v)) [[unlikely]] {
      ++state_resets_;
      reset(0.0);
      v = 0.0;
    }
    last_output_ = v;
    return v;
  }

  double process_recording(double x) noexcept {
    auto& w = boundary_[newest_ ^ 1U];  // becomes the newest sample's boundary signals
    double v = x;
    w[0] = v;
    for (std::size_t i = 0; i < c_.count; ++i) {
      v = step(c_.sections[i], state_[i], v);
      w[i + 1] = v;
    }
    newest_ ^= 1U;
    if (--record_left_ == 0 && swap_pending_) apply_swap();
    return v;
  }

  void apply_swap() noexcept {
    swap_pending_ = false;
    const std::size_t old_count = c_.count;
    c_ = next_;
    const auto& now = boundary_[newest_];
    const auto& before = boundary_[newest_ ^ 1U];
    for (std::size_t i = 0; i < c_.count; ++i) {
      const std::size_t in = i < old_count ? i : old_count;
      const std::size_t out = i + 1 < old_count ? i + 1 : old_count;
      const BiquadCoefficients& k = c_.sections[i];
      state_[i].s2 = k.b2 * now[in] - k.a2 * now[out];
      state_[i].s1 = k.b1 * now[in] - k.a1 * now[out] + k.b2 * before[in] - k.a2 * before[out];
    }
  }
  SosCoefficients c_{};
  SosCoefficients next_{};
  std::array<State, kMaxSections> state_{};
  // Signals at the section boundaries (0 = input, i + 1 = output of section i) for the last two samples.
  std::array<std::array<double, kMaxSections + 1>, 2> boundary_{};
  unsigned newest_{0};
  unsigned record_left_{0};
  bool swap_pending_{false};
  double last_output_{0.0};
  std::uint64_t nonfinite_inputs_{0};
  std::uint64_t state_resets_{0};
};

}  // namespace robodamp::filters
