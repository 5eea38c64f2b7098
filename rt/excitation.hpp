// A command source of the loop beside the controller: the commissioning chirp (robodamp measure, with
// the gain at 0: control off, amplifier enabled). The loop evaluates it each tick on its own clock, the
// sum of the measured dt since the first tick (the supervisor's clock), and hands it to the supervisor
// as TickInput::excitation_v; the supervisor adds it to the controller's command while active, faded
// and clamped to the amplifier's voltage limit like every command. A recording carries the chirp in its
// header, so replay regenerates it bit for bit.
#pragma once

#include <cmath>

#include "units/units.hpp"

namespace robodamp::rt {

// A periodic linear chirp: each period sweeps f0 -> f1 from phase 0. RT-safe.
struct PeriodicChirp {
  bool enabled{false};
  double start_s{0.0};
  double period_s{8.0};
  int periods{0};
  double f0_hz{0.0}, f1_hz{0.0};
  double amplitude_v{0.0};
  // The amplitude rises linearly from 0 over this time from the start (a real cell is never stepped to
  // the full level; the first period, the transient, is discarded anyway). 0: no ramp.
  double ramp_s{0.0};
  // true: start_s is not a time but waits for a start_excitation command (ExcitationClock::start_next_tick).
  bool on_command{false};
  // The signal at time t_s since the first tick (0 outside [start, start + periods x period)).
  [[nodiscard]] double value_v(double t_s) const noexcept {
    if (!enabled || t_s < start_s || t_s >= end_s()) return 0.0;
    const double tau = std::fmod(t_s - start_s, period_s);
    const double phase = kTwoPi * (f0_hz * tau + 0.5 * (f1_hz - f0_hz) * tau * tau / period_s);
    const double level = ramp_s > 0.0 && t_s - start_s < ramp_s ? (t_s - start_s) / ramp_s : 1.0;
    return level * amplitude_v * std::sin(phase);
  }
  [[nodiscard]] double end_s() const noexcept { return start_s + period_s * periods; }
};

// The chirp's clock: value then advance, once per tick, in the loop and in replay alike.
class ExcitationClock {
 public:
  explicit ExcitationClock(const PeriodicChirp& chirp) noexcept : chirp_(chirp) {
    if (chirp_.on_command) chirp_.start_s = kNever;
  }
  [[nodiscard]] double next_v(double dt_s) noexcept {
    const double v = chirp_.value_v(t_s_);
    t_s_ += dt_s;
    return v;
  }
  // An on-command chirp starts (again) at the next tick: called after next_v of the tick that applies the
  // command. Nothing for a chirp with a start time.
  void start_next_tick() noexcept {
    if (chirp_.on_command) chirp_.start_s = t_s_;
  }
  [[nodiscard]] const PeriodicChirp& chirp() const noexcept { return chirp_; }

 private:
  static constexpr double kNever = 1e300;  // an on-command chirp's start before its first command
  PeriodicChirp chirp_;
  double t_s_{0.0};  // the sum of dt before this tick
};

}  // namespace robodamp::rt
