// The one monotonic clock and the one absolute-deadline pacer of robodamp: the real-time loop (rt/loop)
// and the HIL plant emulator (hil/plant_emulator) pace with the same code, and every component that
// stamps or measures time reads CLOCK_MONOTONIC through monotonic_ns(). RT-safe: no allocation, no locks.
#pragma once

#include <cerrno>
#include <cstdint>
#include <ctime>  // clock_nanosleep, clock_gettime (POSIX, through glibc's time.h)

namespace robodamp::rt {

inline constexpr std::int64_t kNsPerS = 1'000'000'000;

// CLOCK_MONOTONIC in nanoseconds.
[[nodiscard]] inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

// CLOCK_MONOTONIC in seconds.
[[nodiscard]] inline double monotonic_s() noexcept { return static_cast<double>(monotonic_ns()) * 1e-9; }

// Sleeps until an absolute CLOCK_MONOTONIC time (restarted after a signal).
inline void sleep_until_ns(std::int64_t t_ns) noexcept {
  const timespec ts{static_cast<time_t>(t_ns / kNsPerS), static_cast<long>(t_ns % kNsPerS)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {}
}

// Absolute-deadline pacing: each period's deadline is the previous one plus the period (no drift from
// the time spent computing). A wake-up late by a whole period or more skips the periods missed (the
// deadline moves ahead by them), so a late thread never catches up in a burst.
class DeadlinePacer {
 public:
  struct Wake {
    std::int64_t wake_ns{0};  // when the thread woke
    std::int64_t late_ns{0};  // how long after the deadline
    std::uint64_t missed{0};  // whole periods skipped
  };

  DeadlinePacer(std::int64_t period_ns, std::int64_t first_deadline_ns) noexcept
      : period_ns_(period_ns), deadline_ns_(first_deadline_ns) {}

  // Sleeps until the current deadline.
  Wake wait() noexcept {
    sleep_until_ns(deadline_ns_);
    Wake w;
    w.wake_ns = monotonic_ns();
    w.late_ns = w.wake_ns - deadline_ns_;
    if (w.late_ns >= period_ns_) {
      w.missed = static_cast<std::uint64_t>(w.late_ns / period_ns_);
      deadline_ns_ += static_cast<std::int64_t>(w.missed) * period_ns_;
    }
    return w;
  }
  // The next period.
  void advance() noexcept { deadline_ns_ += period_ns_; }

  [[nodiscard]] std::int64_t deadline_ns() const noexcept { return deadline_ns_; }
  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_; }

 private:
  std::int64_t period_ns_;
  std::int64_t deadline_ns_;
};

}  // namespace robodamp::rt
