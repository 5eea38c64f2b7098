// The sensor and actuator over CAN (docs/physics.md §1's DAQ and amplifier, on a CAN bus): the loop's
// SensorSource and ActuatorSink on one CanChannel. Everything here runs on the real-time thread: non-
// blocking socket calls, no allocation, no exceptions, no logging. Problems are counted (counters() is
// safe to read from any thread) and reported to the supervisor as driver faults:
// - sensor: error frames; bus-off (until the controller restarts or the back-off has passed); a peer
//   that has gone; lost frames (counter gaps) at or above can.lost_frames_fault within one second. A
//   repeated counter is a stale frame: not fresh, so the supervisor's stale-sensor trip sees a stuck DAQ.
// - actuator: bus-off, a transmit queue that stays full (ENOBUFS / EAGAIN, three times running) or any
//   other send failure (the link has gone, the interface is down). Transmission then backs
//   off (can.backoff_initial_s, doubling up to can.backoff_max_s) and is retried: never a dead driver.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "config/can_config.hpp"
#include "fields/fields.hpp"
#include "drivers/can_channel.hpp"
#include "drivers/can_codec.hpp"
#include "rt/io.hpp"

namespace robodamp::drivers {

struct CanCounters {
  std::uint64_t rx_frames{0};     // sensor frames decoded
  std::uint64_t rx_other{0};      // frames with another identifier (fd transport: no kernel filter)
  std::uint64_t rx_malformed{0};  // short, oversize, remote or non-FD frames for the sensor mapping
  std::uint64_t lost_frames{0};   // counter gaps
  std::uint64_t stale_frames{0};  // repeated counters
  std::uint64_t error_frames{0};
  std::uint64_t bus_off{0};    // bus-off events
  std::uint64_t restarts{0};   // controller restarted after bus-off
  std::uint64_t rx_errors{0};  // receive calls that failed (other than nothing waiting)
  std::uint64_t tx_frames{0};
  std::uint64_t tx_queue_full{0};    // ENOBUFS / EAGAIN
  std::uint64_t tx_errors{0};        // other send failures
  std::uint64_t tx_skipped{0};       // commands not sent while backing off
  std::uint64_t tx_clipped{0};       // commands outside the command field's range
  std::uint64_t rx_held{0};          // de-jitter: frames held over to the next tick
  std::uint64_t rx_skipped{0};       // de-jitter: frames skipped (backlog, or resync to the newest)
  std::uint64_t reconnects{0};       // transports handed over after the peer went away (offer_channel)
  std::uint64_t resync_backoffs{0};  // de-jitter: a resync left a tick without a frame; its interval doubled
};

// CanCounters' JSON keys (the run summary's "can") and their words in its text line.
[[nodiscard]] constexpr auto field_list(fields::Tag<CanCounters>) {
  using C = CanCounters;
  using F = fields::Field<C, std::uint64_t>;
  return std::tuple{F{"rx_frames", &C::rx_frames, "sensor frames"},
                    F{"rx_other", &C::rx_other, "other ids"},
                    F{"rx_malformed", &C::rx_malformed, "malformed"},
                    F{"lost_frames", &C::lost_frames, "lost"},
                    F{"stale_frames", &C::stale_frames, "stale"},
                    F{"error_frames", &C::error_frames, "error frames"},
                    F{"bus_off", &C::bus_off, "bus-off"},
                    F{"restarts", &C::restarts, "restarts"},
                    F{"rx_errors", &C::rx_errors, "receive errors"},
                    F{"tx_frames", &C::tx_frames, "commands sent"},
                    F{"tx_queue_full", &C::tx_queue_full, "queue full"},
                    F{"tx_errors", &C::tx_errors, "send errors"},
                    F{"tx_skipped", &C::tx_skipped, "commands skipped"},
                    F{"tx_clipped", &C::tx_clipped, "commands clipped"},
                    F{"rx_held", &C::rx_held, "held over (de-jitter)"},
                    F{"rx_skipped", &C::rx_skipped, "skipped (de-jitter)"},
                    F{"reconnects", &C::reconnects, "reconnects"},
                    F{"resync_backoffs", &C::resync_backoffs, "resyncs backed off"}};
}
static_assert(fields::lists_every_member<CanCounters>(), "each counter in CanCounters' field list");

class CanDriver final : public rt::SensorSource, public rt::ActuatorSink {
 public:
  CanDriver(const config::CanConfig& cfg, CanChannel channel, double loop_rate_hz);
  ~CanDriver() override;
  CanDriver(const CanDriver&) = delete;
  CanDriver& operator=(const CanDriver&) = delete;

  // Lockstep pacing (virtual clock against the HIL emulator): each read waits up to wait_s for the
  // tick's sensor frame, which the emulator sends once it has the previous command. 0 (the default, and
  // always on the wall clock): never wait.
  void set_lockstep_wait(double wait_s) noexcept { lockstep_wait_ns_ = static_cast<std::int64_t>(wait_s * 1e9); }
  // Wall clock against a sensor node on its own clock at the loop rate: when the two clocks' phases are
  // close, wake-up jitter delivers 0 frames in one tick and 2 in the next. With the de-jitter slot on,
  // the second of two frames is held for the next tick, so every tick gets a fresh sample (one period
  // older when the slot is in use). After resync_ticks ticks running with the slot in use and exactly
  // one new frame each, the held frame is skipped to get the latency back. A resync followed within
  // kResyncProbeTicks by a tick without a frame found the phases still close: it cost a stale sample, so
  // the interval doubles (up to kResyncMaxTicks) before the next try. Off by default.
  void set_dejitter(bool on, std::uint64_t resync_ticks = 1000) noexcept {
    dejitter_ = on;
    resync_ticks_ = resync_ticks;
  }
  static constexpr std::uint64_t kResyncProbeTicks = 50;
  static constexpr std::uint64_t kResyncMaxTicks = std::uint64_t{1} << 20;  // 210 s at 5 kHz

  [[nodiscard]] rt::SensorSample read(std::uint64_t tick) noexcept override;
  [[nodiscard]] rt::ActuatorStatus write(double command_v, std::uint64_t tick) noexcept override;

  // Before the loop starts (wall clock): discards what queued up while the controller was starting (a
  // DAQ streams from power-up; the socket's queue overflowed meanwhile), so those are not counted as
  // lost frames. Returns how many were discarded.
  std::uint64_t flush() noexcept;

  [[nodiscard]] CanCounters counters() const noexcept;
  [[nodiscard]] bool bus_off() const noexcept { return bus_off_; }
  // Any thread: the peer of a connected transport (the HIL emulator's socket) has gone away.
  [[nodiscard]] bool link_lost() const noexcept { return link_lost_.load(std::memory_order_relaxed); }
  // From a non-real-time thread: a new connection to take over at the loop's next read (the emulator
  // came back). The loop swaps descriptors without a system call and leaves the old one for
  // take_retired_fd(). False while an earlier hand-over is still pending.
  bool offer_channel(CanChannel&& c) noexcept;
  // The descriptor the loop let go of, to be closed off the real-time thread; -1 when none.
  [[nodiscard]] int take_retired_fd() noexcept { return retired_fd_.exchange(-1, std::memory_order_acq_rel); }
  [[nodiscard]] double backoff_s() const noexcept { return static_cast<double>(backoff_ticks_) / rate_hz_; }
  [[nodiscard]] std::int64_t last_rx_timestamp_ns() const noexcept { return last_rx_ns_; }

 private:
  // Counters are written by the loop thread only and read by others: relaxed atomics.
  struct AtomicCounters {
    std::atomic<std::uint64_t> rx_frames{0}, rx_other{0}, rx_malformed{0}, lost_frames{0}, stale_frames{0},
        error_frames{0}, bus_off{0}, restarts{0}, rx_errors{0}, tx_frames{0}, tx_queue_full{0}, tx_errors{0},
        tx_skipped{0}, tx_clipped{0}, rx_held{0}, rx_skipped{0}, reconnects{0}, resync_backoffs{0};
  };
  static void bump(std::atomic<std::uint64_t>& c, std::uint64_t n = 1) noexcept {
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  void enter_backoff(std::uint64_t tick) noexcept;
  void take_over_pending() noexcept;

  config::CanConfig cfg_;
  CanChannel channel_;
  double rate_hz_;
  AtomicCounters n_;
  // Sensor side.
  double last_value_{0.0};
  bool have_counter_{false};
  std::uint32_t last_counter_{0};
  std::uint32_t counter_mask_{0};
  // Ticks of the most recent lost frames (ring): a fault when the lost_frames_fault-th latest is within
  // the last second.
  static constexpr std::size_t kLossRing = 1024;
  std::array<std::uint64_t, kLossRing> loss_ticks_{};
  std::uint64_t losses_{0};
  std::uint64_t window_ticks_{1};
  std::int64_t last_rx_ns_{-1};
  std::atomic<bool> link_lost_{false};
  std::atomic<int> pending_fd_{-1}, retired_fd_{-1};
  bool rx_fault_{false};
  // Bus state and transmit back-off.
  bool bus_off_{false};
  std::uint64_t retry_tick_{0};
  std::uint64_t backoff_ticks_{0}, backoff_initial_ticks_{1}, backoff_max_ticks_{1};
  int consecutive_tx_failures_{0};
  std::uint32_t tx_counter_{0};
  std::int64_t lockstep_wait_ns_{0};
  bool dejitter_{false};
  bool held_{false};
  double held_value_{0.0};
  std::uint64_t resync_ticks_{1000}, steady_ticks_{0};
  std::uint64_t since_resync_{kResyncProbeTicks};  // ticks since the last resync (probing up to kResyncProbeTicks)
};

}  // namespace robodamp::drivers
