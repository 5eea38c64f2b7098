// The fixed-rate loop. Each tick: wait for the deadline, read the sensor, take one operator command,
// step the supervisor (and its controller), write the actuator, ask for the amplifier enable, push a
// telemetry frame, record the timing. Runs on the calling thread (rt::RealtimeThread sets that thread
// up); after construction it allocates nothing, takes no lock, does no blocking I/O, throws nothing and
// logs nothing (tests/test_rt_allocation counts).
//
// Wall clock: clock_nanosleep(TIMER_ABSTIME) on CLOCK_MONOTONIC, deadline = previous deadline + period;
// a late wake-up skips the ticks it missed (counted, never run in a burst) and is an overrun, as is a tick
// whose work ends past the next deadline; the measured dt goes to the supervisor and the frame.
// Commands, in order of precedence at a tick: the end of the run, a scheduled command, the tick policy's
// (runtime/arming_policy), then one posted by another thread.
// Virtual clock: ticks back to back as fast as possible, dt = period exactly, no timing in the frames:
// the same inputs give bit-identical frames run to run.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "rt_settings/rt_settings.hpp"
#include "rt/clock.hpp"
#include "rt/excitation.hpp"
#include "rt/io.hpp"
#include "rt/spsc_ring.hpp"
#include "rt/supervisor.hpp"
#include "rt/telemetry_frame.hpp"
#include "rt/tick_policy.hpp"
#include "rt/timing_histogram.hpp"

namespace robodamp::rt {

struct LoopStats {
  std::uint64_t ticks_run{0};
  std::uint64_t last_tick{0};
  std::uint64_t missed_ticks{0};
  std::uint64_t overruns{0};
  std::uint64_t ring_drops{0};
  std::uint64_t ring_waits{0};         // virtual clock: times the loop waited for the drain (never drops)
  double elapsed_s{0.0};               // wall time of the run
  std::int64_t start_monotonic_ns{0};  // CLOCK_MONOTONIC of tick 0's deadline: a frame's time_s after it (wall clock)
  TimingHistogram wake_latency;        // wake-up minus deadline (wall clock)
  TimingHistogram compute;             // wake-up to end of the tick's work
};

class Loop {
 public:
  // On the virtual clock, how far the loop may run ahead of the telemetry drain (frames; 0.2 s at 5 kHz).
  static constexpr std::size_t kVirtualLeadFrames = 1024;

  Loop(double rate_hz, ClockKind clock, Supervisor& supervisor, SensorSource& sensor, ActuatorSink& actuator,
       AmplifierIo& io, SpscRing<TelemetryFrame>* telemetry);

  // From any non-real-time thread (operator, Modbus pose, DDS parameter requests): queue a command for
  // the next tick boundary. False when the queue is full. The producers take turns under a mutex; the
  // loop only pops the ring and never waits for it.
  bool post(const OperatorCommand& c) noexcept {
    std::lock_guard<std::mutex> lock(post_mutex_);
    return commands_.push(c);
  }
  // Before run(): a command for a given tick (a script: tests, virtual-clock runs). A scheduled command
  // takes the tick before posted ones; if its tick was skipped it runs at the next tick.
  void schedule(std::uint64_t tick, const OperatorCommand& c);
  // Before run(): a command source added to the controller's (the commissioning chirp), on the clock of
  // the measured dt from this run's first tick.
  void set_excitation(const PeriodicChirp& chirp) noexcept { excitation_ = ExcitationClock(chirp); }
  [[nodiscard]] const PeriodicChirp& excitation() const noexcept { return excitation_.chirp(); }
  // Before run(): the policy asked each tick when no scripted command is due (arming); nullptr = none.
  void set_policy(TickPolicy* policy) noexcept { policy_ = policy; }
  // From any thread: end the run as if its duration were over (disarm, ramp, return).
  void request_stop() noexcept { stop_.store(true, std::memory_order_relaxed); }
  // The flag read each tick as SIGINT/SIGTERM (default: rt::shutdown_signal()).
  void set_shutdown_flag(const std::atomic<int>* flag) noexcept { shutdown_ = flag; }

  // Runs until `duration_ticks` nominal periods have passed (or request_stop / a shutdown signal), then
  // disarms and keeps running until the supervisor is safe (amplifier off, command zero). Allocation-free.
  void run(std::uint64_t duration_ticks) noexcept;

  [[nodiscard]] const LoopStats& stats() const noexcept { return *stats_; }
  [[nodiscard]] double period_s() const noexcept { return static_cast<double>(period_ns_) * 1e-9; }
  [[nodiscard]] ClockKind clock() const noexcept { return clock_; }

 private:
  // One run's state between ticks (on the stack of run(); nothing allocated).
  struct Run {
    DeadlinePacer pacer;
    std::uint64_t end_tick;
    std::uint64_t tail_ticks;  // ticks after the end for the slowest ramp to finish
    std::int64_t prev_wake_ns;
    ActuatorStatus actuator{};
    bool overrun{false};  // the previous tick's work ended past the next deadline
    bool ending{false};
    std::uint64_t ending_ticks{0};
  };
  struct Pace {
    std::int64_t wake_ns{0}, latency_ns{0};
    std::uint64_t missed{0};
    double dt_s{0.0};
  };
  // The tick's stages, in order (all noexcept, allocation-free).
  Pace pace(Run& r) noexcept;
  [[nodiscard]] TickInput inputs(const Run& r, const Pace& p) noexcept;
  [[nodiscard]] OperatorCommand next_command(Run& r) noexcept;
  void account(Run& r, const Pace& p, const TickInput& in) noexcept;
  void publish(const Pace& p, const TickInput& in, const TickOutput& out) noexcept;

  std::int64_t period_ns_;
  ClockKind clock_;
  Supervisor& sup_;
  SensorSource& sensor_;
  ActuatorSink& actuator_;
  AmplifierIo& io_;
  SpscRing<TelemetryFrame>* telemetry_;
  SpscRing<OperatorCommand> commands_{64};
  std::mutex post_mutex_;
  std::vector<std::pair<std::uint64_t, OperatorCommand>> scheduled_;
  std::size_t next_scheduled_{0};
  std::atomic<bool> stop_{false};
  const std::atomic<int>* shutdown_;
  TickPolicy* policy_{nullptr};
  ExcitationClock excitation_{PeriodicChirp{}};
  std::unique_ptr<LoopStats> stats_;
  std::uint64_t tick_{0};
  std::int64_t last_compute_ns_{0};  // the tick's compute time, for its frame
};

}  // namespace robodamp::rt
