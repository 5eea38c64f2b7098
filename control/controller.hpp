// The DVF controller (Eq. 8): accelerometer samples in, amplifier volts out. No clock, no I/O; every
// member after construction is RT-safe: no allocation, locking, exceptions or logging.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "control/controller_params.hpp"
#include "filters/biquad.hpp"

namespace robodamp::control {

struct ControllerCounters {
  std::uint64_t samples{0};
  std::uint64_t nonfinite_inputs{0};     // never entered the filter state
  std::uint64_t filter_state_resets{0};  // non-finite filter output (overflow), state cleared
  std::uint64_t force_limited{0};        // command force clipped at the actuator force limit
  std::uint64_t voltage_limited{0};      // clipped at the amplifier voltage range
  std::uint64_t slew_limited{0};         // clipped at the slew-rate limit
  std::uint64_t rejected_requests{0};    // gain or parameter requests refused (out of range, other rate)
  std::uint64_t spindle_refused{0};      // spindle speeds refused (NaN, negative, above rpm_max): notches parked
};

enum class RequestStatus { kAccepted, kRejectedOutOfRange, kRejectedSampleRate };

// Largest K a request may ask for; the configuration enforces the same bound.
inline constexpr double kMaxGainNsPerM = 1e5;

class Controller final {
 public:
  explicit Controller(const ControllerParams& p) noexcept
      : p_(p), cascade_(p.sections), notches_(p.harmonic_notch, p.fs_hz), dt_s_(1.0 / p.fs_hz) {
    target_gain_ = p.gain_ns_per_m;  // the spindle is stopped: outside every band of a speed schedule
    scale_ = target_scale_ = output_scale(p_, target_gain_);
  }

  // RT-safe. One loop sample: acceleration at the actuator location (m/s^2) -> amplifier command (V).
  [[nodiscard]] double update(double accel_mps2) noexcept {
    ++counters_.samples;
    const double shaped = notches_.process(cascade_.process(accel_mps2));
    filtered_ = shaped;
    if (pending_) (void)shadow_.process(accel_mps2);  // the incoming chain warms up on the same signal
    advance_ramp();
    advance_derate();
    double force_n = derate_ * scale_ * shaped;  // derating * polarity * K * chain(accel), newtons
    if (std::abs(force_n) > p_.force_limit_n) {
      force_n = std::copysign(p_.force_limit_n, force_n);
      ++counters_.force_limited;
    }
    double volts = force_n / p_.actuator_constant_n_per_v;
    if (std::abs(volts) > p_.voltage_limit_v) {
      volts = std::copysign(p_.voltage_limit_v, volts);
      ++counters_.voltage_limited;
    }
    const double max_step_v = p_.slew_rate_v_per_s * dt_s_;
    if (std::abs(volts - command_v_) > max_step_v) {
      volts = command_v_ + std::copysign(max_step_v, volts - command_v_);
      ++counters_.slew_limited;
    }
    command_v_ = volts;
    force_n_ = force_n;
    return volts;
  }

  // RT-safe. Filter states at steady state for a constant input; the command restarts from there
  // (zero for a chain with a high-pass), without a slew transient.
  void reset(double accel_mps2) noexcept {
    cascade_.reset(accel_mps2);
    notches_.reset(cascade_.last_output());
    if (pending_) shadow_.reset(accel_mps2);
    const double f = scale_ * cascade_.last_output();
    force_n_ = std::copysign(std::min(std::abs(f), p_.force_limit_n), f);
    command_v_ = std::copysign(std::min(std::abs(force_n_ / p_.actuator_constant_n_per_v), p_.voltage_limit_v), f);
  }

  // RT-safe. The spindle speed the harmonic notches follow (tooth frequency = rpm x teeth / 60); 0 =
  // stopped. A NaN, negative or above-range speed, or one where the analysis refused the notches
  // (ControllerParams::refused_rpm), is refused, counted, and parks the notches. With a speed schedule
  // (ControllerParams::speed_bands) the speed also sets K.
  RequestStatus set_spindle_rpm(double rpm) noexcept {
    bool refused = !std::isfinite(rpm) || rpm < 0.0 || rpm > p_.spindle_rpm_max;
    for (std::size_t i = 0; i < p_.refused_rpm_count; ++i)
      refused = refused || (rpm >= p_.refused_rpm[i].first && rpm <= p_.refused_rpm[i].second);
    if (refused) {
      ++counters_.spindle_refused;
      spindle_rpm_ = 0.0;  // parked (a later hand-over keeps them parked)
      notches_.set_tooth_frequency(0.0);
      // A speed the notches refuse still turns the spindle: the schedule follows it (an impossible speed:
      // outside every band).
      schedule_rpm_ = std::isfinite(rpm) && rpm >= 0.0 && rpm <= p_.spindle_rpm_max ? rpm : 0.0;
      follow_speed_schedule();
      return RequestStatus::kRejectedOutOfRange;
    }
    spindle_rpm_ = schedule_rpm_ = rpm;
    notches_.set_tooth_frequency(rpm * p_.spindle_teeth / 60.0);
    follow_speed_schedule();
    return RequestStatus::kAccepted;
  }

  // RT-safe. Ramps K to the new value over the configured ramp time; refuses what the configuration
  // would refuse. With a speed schedule, K inside a band is the band's (refused here); outside every band
  // (the spindle stopped) the request sets the K used there.
  [[nodiscard]] RequestStatus set_gain(double gain_ns_per_m) noexcept {
    if (!std::isfinite(gain_ns_per_m) || gain_ns_per_m < 0.0 || gain_ns_per_m > kMaxGainNsPerM || in_speed_band()) {
      ++counters_.rejected_requests;
      return RequestStatus::kRejectedOutOfRange;
    }
    if (p_.speed_scheduled()) p_.gain_ns_per_m = gain_ns_per_m;
    ramp_gain_to(gain_ns_per_m);
    return RequestStatus::kAccepted;
  }
  // RT-safe. K to this value over the ramp, whatever the schedule says (the supervisor's safe K of 0 where a
  // band's set was refused); the next speed change follows the schedule again.
  void ramp_gain_to(double gain_ns_per_m) noexcept {
    target_gain_ = gain_ns_per_m;
    if (!pending_) start_ramp(output_scale(p_, target_gain_));  // during a hand-over: applied at fade-in
  }
  // RT-safe. The supervisor's derating (docs/realtime_loop.md, "Keeping damping when the cut chatters"): a
  // factor in [0, 1] on the force command before the limits, reached linearly over ramp_s (0: at once). K,
  // its ramps, hand-overs and the speed schedule are untouched: derating multiplies whatever they give.
  void set_derate(double factor, double ramp_s) noexcept {
    derate_target_ = std::isfinite(factor) ? std::clamp(factor, 0.0, 1.0) : 0.0;
    const double n = std::isfinite(ramp_s) && ramp_s > 0.0 ? std::ceil(ramp_s * p_.fs_hz) : 0.0;
    derate_left_ = static_cast<std::uint64_t>(n);
    derate_step_ = derate_left_ > 0 ? (derate_target_ - derate_) / n : 0.0;
    if (derate_left_ == 0) derate_ = derate_target_;
  }
  [[nodiscard]] double derate() const noexcept { return derate_; }
  [[nodiscard]] double derate_target() const noexcept { return derate_target_; }
  // A speed schedule's band holds the spindle's speed (K is the band's).
  [[nodiscard]] bool in_speed_band() const noexcept { return p_.speed_band_of(schedule_rpm_) < p_.speed_band_count; }

  // RT-safe (copies fixed-size structs). Hands over to a new parameter set at cycle boundaries: the
  // incoming chain starts from the running chain's signal history (sections shared by both chains
  // carry over exactly) and runs in the shadow on the same samples while the output fades to zero;
  // it runs for the incoming chain's settling time (its slowest pole) before the fade-out ends, then
  // it takes over and the output fades in with the new polarity, gain and limits. fade_first (a speed
  // schedule's hand-over: the running chain may be worse than none at the new speed): the output fades to
  // zero at once and stays there while the incoming chain warms up.
  [[nodiscard]] RequestStatus request_params(const ControllerParams& next, bool fade_first = false) noexcept {
    if (next.fs_hz != p_.fs_hz) {
      ++counters_.rejected_requests;
      return RequestStatus::kRejectedSampleRate;
    }
    if (!std::isfinite(next.gain_ns_per_m) || next.gain_ns_per_m < 0.0 || next.gain_ns_per_m > kMaxGainNsPerM ||
        next.sections.count > filters::kMaxSections) {
      ++counters_.rejected_requests;
      return RequestStatus::kRejectedOutOfRange;
    }
    next_ = next;
    shadow_ = cascade_;  // an exact copy: identical to the running chain until its swap
    shadow_.request_swap(next.sections);
    pending_ = true;
    target_gain_ = next.scheduled_gain_ns_per_m(schedule_rpm_);
    // At least the two samples the shadow's swap needs, however short the ramp.
    const double fade = std::ceil(p_.gain_ramp_s * p_.fs_hz), settle = std::ceil(next.settle_s * p_.fs_hz);
    if (fade_first) {
      warmup_left_ = static_cast<std::uint64_t>(std::max(settle, fade) + 2.0);
      start_ramp(0.0);
      return RequestStatus::kAccepted;
    }
    warmup_left_ = settle > fade + 2.0 ? static_cast<std::uint64_t>(settle - fade) : 2;
    return RequestStatus::kAccepted;
  }

  [[nodiscard]] const ControllerCounters& counters() const noexcept {
    counters_.nonfinite_inputs = cascade_.nonfinite_input_count();
    counters_.filter_state_resets = cascade_.state_reset_count();
    return counters_;
  }
  // Current (ramping) K.
  [[nodiscard]] double gain_ns_per_m() const noexcept { return scale_ / (p_.polarity * p_.sections_gain); }
  [[nodiscard]] double target_gain_ns_per_m() const noexcept { return target_gain_; }
  [[nodiscard]] bool handover_pending() const noexcept { return pending_; }
  [[nodiscard]] double command_v() const noexcept { return command_v_; }
  // The chain's output for the last sample: the velocity estimate the gain acts on, m/s.
  [[nodiscard]] double filtered_mps() const noexcept { return p_.sections_gain * filtered_; }
  [[nodiscard]] double force_command_n() const noexcept { return force_n_; }
  [[nodiscard]] const ControllerParams& params() const noexcept { return p_; }
  [[nodiscard]] const filters::HarmonicNotchBank& notches() const noexcept { return notches_; }
  [[nodiscard]] double spindle_rpm() const noexcept { return spindle_rpm_; }
  // The speed a speed schedule follows (the spindle's, also where the notches park).
  [[nodiscard]] double schedule_rpm() const noexcept { return schedule_rpm_; }

 private:
  static double output_scale(const ControllerParams& p, double gain) noexcept {
    return p.polarity * gain * p.sections_gain;
  }

  // A speed schedule's K at the spindle speed now, ramped like any gain change (applied at fade-in during a
  // hand-over).
  // A band of another set keeps K as it is: the supervisor hands over to that set, and the hand-over fades out.
  // During a hand-over the incoming set's K is what follows (applied at its fade-in).
  void follow_speed_schedule() noexcept {
    const ControllerParams& p = pending_ ? next_ : p_;
    if (!p.speed_scheduled()) return;
    if (!pending_ && p.scheduled_set(schedule_rpm_) != p.set_index) return;
    const double k = p.scheduled_gain_ns_per_m(schedule_rpm_);
    if (k != target_gain_) ramp_gain_to(k);
  }

  void start_ramp(double target_scale) noexcept {
    target_scale_ = target_scale;
    const double n = std::ceil(p_.gain_ramp_s * p_.fs_hz);
    ramp_left_ = n >= 1.0 ? static_cast<std::uint64_t>(n) : 0;
    ramp_step_ = ramp_left_ > 0 ? (target_scale_ - scale_) / static_cast<double>(ramp_left_) : 0.0;
    if (ramp_left_ == 0) finish_ramp();
  }

  void advance_derate() noexcept {
    if (derate_left_ == 0) return;
    derate_ += derate_step_;
    if (--derate_left_ == 0) derate_ = derate_target_;
  }

  void advance_ramp() noexcept {
    if (warmup_left_ > 0 && --warmup_left_ == 0) {
      if (ramp_left_ == 0 && scale_ == 0.0) {  // faded out already (fade_first): swap now
        finish_ramp();
        return;
      }
      start_ramp(0.0);
    }
    if (ramp_left_ == 0) return;
    scale_ += ramp_step_;
    if (--ramp_left_ == 0) finish_ramp();
  }

  void finish_ramp() noexcept {
    scale_ = target_scale_;
    // Faded out: hand over, then fade in. Only the fade-out the warm-up started ends in a swap: a hand-over
    // asked for while the last one still faded in waits for its own warm-up and fade-out.
    if (pending_ && warmup_left_ == 0) {
      pending_ = false;
      cascade_ = shadow_;
      p_ = next_;  // same fs_hz (request_params refuses another rate), so dt_s_ stands
      notches_.configure(p_.harmonic_notch, p_.fs_hz);  // the notches' state and centre carry over
      notches_.set_tooth_frequency(spindle_rpm_ * p_.spindle_teeth / 60.0);
      start_ramp(output_scale(p_, target_gain_));
    }
  }

  ControllerParams p_;
  ControllerParams next_{};
  filters::BiquadCascade cascade_;
  filters::BiquadCascade shadow_;
  filters::HarmonicNotchBank notches_;
  double dt_s_;
  double spindle_rpm_{0.0};   // what the notches follow (0: parked)
  double schedule_rpm_{0.0};  // what the speed schedule follows: the spindle's speed, parked or not
  double target_gain_{0.0};
  double scale_{0.0}, target_scale_{0.0}, ramp_step_{0.0};
  std::uint64_t ramp_left_{0};
  std::uint64_t warmup_left_{0};
  bool pending_{false};
  double command_v_{0.0};
  double force_n_{0.0};
  double derate_{1.0}, derate_target_{1.0}, derate_step_{0.0};
  std::uint64_t derate_left_{0};
  double filtered_{0.0};
  mutable ControllerCounters counters_{};
};

}  // namespace robodamp::control
