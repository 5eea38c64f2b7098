#include "drivers/can_driver.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <linux/can/error.h>
#include <unistd.h>

namespace robodamp::drivers {

namespace {
constexpr int kMaxFramesPerTick = 64;  // bounded work per tick however much is queued
constexpr int kTxFailuresToFault = 3;  // consecutive full queues before the actuator is reported faulty
}  // namespace

CanDriver::CanDriver(const config::CanConfig& cfg, CanChannel channel, double loop_rate_hz)
    : cfg_(cfg), channel_(std::move(channel)), rate_hz_(loop_rate_hz) {
  if (cfg_.sensor.counter) counter_mask_ = counter_mask(*cfg_.sensor.counter);
  window_ticks_ = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(loop_rate_hz)));
  backoff_initial_ticks_ =
      std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(cfg_.backoff_initial_s * loop_rate_hz)));
  backoff_max_ticks_ =
      std::max(backoff_initial_ticks_, static_cast<std::uint64_t>(std::llround(cfg_.backoff_max_s * loop_rate_hz)));
}

CanDriver::~CanDriver() {
  for (const int fd : {pending_fd_.load(), retired_fd_.load()})
    if (fd >= 0) ::close(fd);
}

void CanDriver::enter_backoff(std::uint64_t tick) noexcept {
  backoff_ticks_ = backoff_ticks_ == 0 ? backoff_initial_ticks_ : std::min(2 * backoff_ticks_, backoff_max_ticks_);
  retry_tick_ = tick + backoff_ticks_;
}

bool CanDriver::offer_channel(CanChannel&& c) noexcept {
  int expected = -1;
  const int fd = c.fd();
  if (!pending_fd_.compare_exchange_strong(expected, fd, std::memory_order_acq_rel)) return false;
  (void)c.release();
  return true;
}

// RT-safe: descriptors change hands, nothing is opened or closed here.
void CanDriver::take_over_pending() noexcept {
  if (pending_fd_.load(std::memory_order_acquire) < 0 || retired_fd_.load(std::memory_order_acquire) >= 0) return;
  const int fd = pending_fd_.exchange(-1, std::memory_order_acq_rel);
  retired_fd_.store(channel_.release(), std::memory_order_release);
  channel_ = CanChannel::adopt(fd);  // nothing to close: released above
  link_lost_.store(false, std::memory_order_relaxed);
  have_counter_ = false;  // a new sender: its counter starts where it starts
  held_ = false;
  bump(n_.reconnects);
}

// long: the real-time read path: drain, decode, counter and de-jitter in one pass without calls that could allocate; left whole
rt::SensorSample CanDriver::read(std::uint64_t tick) noexcept {
  take_over_pending();
  bool fresh = false;
  int arrived = 0;
  double sample = last_value_;
  if (dejitter_ && held_) {  // last tick's second frame is this tick's sample
    sample = held_value_;
    held_ = false;
    fresh = true;
  }
  rx_fault_ = false;
  for (int i = 0; i < kMaxFramesPerTick; ++i) {
    canfd_frame f{};
    std::int64_t ts = 0;
    int n = channel_.receive(f, ts);
    if (n == 0 && i == 0 && lockstep_wait_ns_ > 0 && channel_.wait_readable(lockstep_wait_ns_))
      n = channel_.receive(f, ts);
    if (n == 0) break;
    if (n == -ENOTCONN) {
      link_lost_.store(true, std::memory_order_relaxed);
      break;
    }
    if (n < 0) {
      bump(n_.rx_errors);
      rx_fault_ = true;
      break;
    }
    link_lost_.store(false, std::memory_order_relaxed);
    if (n != CAN_MTU && n != CANFD_MTU) {
      bump(n_.rx_malformed);
      continue;
    }
    if (f.can_id & CAN_ERR_FLAG) {
      bump(n_.error_frames);
      if (f.can_id & CAN_ERR_BUSOFF) {
        if (!bus_off_) bump(n_.bus_off);
        bus_off_ = true;
        enter_backoff(tick);
      }
      if (f.can_id & CAN_ERR_RESTARTED) {
        if (bus_off_) bump(n_.restarts);
        bus_off_ = false;
      }
      continue;
    }
    const Decoded d = decode(cfg_.sensor, f, n);
    if (d.error == DecodeError::kWrongId) {
      bump(n_.rx_other);
      continue;
    }
    if (d.error != DecodeError::kNone) {
      bump(n_.rx_malformed);
      continue;
    }
    if (cfg_.sensor.counter && have_counter_) {
      const CounterStep step = counter_step(last_counter_, d.counter, counter_mask_);
      if (step.repeated) {
        bump(n_.stale_frames);
        continue;
      }
      if (step.lost > 0) {
        bump(n_.lost_frames, step.lost);
        for (std::uint32_t k = 0; k < step.lost && k < kLossRing; ++k) loss_ticks_[losses_++ % kLossRing] = tick;
      }
    }
    last_counter_ = d.counter;
    have_counter_ = true;
    last_rx_ns_ = ts;
    bump(n_.rx_frames);
    ++arrived;
    if (!dejitter_ || !fresh) {
      sample = d.value;
    } else if (!held_) {
      held_value_ = d.value, held_ = true;
      bump(n_.rx_held);
    } else {  // a backlog beyond one frame: move on to the newer ones
      sample = held_value_, held_value_ = d.value;
      bump(n_.rx_skipped);
    }
    fresh = true;
  }
  if (dejitter_) {
    // A tick without a frame soon after a resync: the phases are still close, try again later.
    if (since_resync_ < kResyncProbeTicks) {
      ++since_resync_;
      if (!fresh) {
        resync_ticks_ = std::min(2 * resync_ticks_, kResyncMaxTicks);
        since_resync_ = kResyncProbeTicks;
        bump(n_.resync_backoffs);
      }
    }
    // Exactly one frame per tick while one is held: the phase is steady; after resync_ticks of it, drop
    // the held frame's extra period of latency.
    steady_ticks_ = held_ && arrived == 1 ? steady_ticks_ + 1 : 0;
    if (held_ && steady_ticks_ >= resync_ticks_) {
      sample = held_value_, held_ = false, steady_ticks_ = 0;
      since_resync_ = 0;
      bump(n_.rx_skipped);
    }
  }
  last_value_ = sample;
  const auto limit = static_cast<std::uint64_t>(cfg_.lost_frames_fault);
  const bool too_many_lost = losses_ >= limit && tick < loss_ticks_[(losses_ - limit) % kLossRing] + window_ticks_;
  return {sample, fresh, !(bus_off_ || link_lost_.load(std::memory_order_relaxed) || rx_fault_ || too_many_lost)};
}

rt::ActuatorStatus CanDriver::write(double command_v, std::uint64_t tick) noexcept {
  // Bus-off without a restart notice: once the back-off has passed, try again (the controller may have
  // restarted without telling, e.g. restart-ms on an interface that does not report it).
  if (bus_off_ && tick >= retry_tick_) bus_off_ = false;
  if (tick < retry_tick_) {
    bump(n_.tx_skipped);
    return {false, false};
  }
  const Encoded e = encode(cfg_.command, cfg_.fd, command_v, tx_counter_);
  if (e.clipped) bump(n_.tx_clipped);
  const int rc = channel_.send(e.frame, e.frame_bytes);
  if (rc == 0) {
    ++tx_counter_;
    bump(n_.tx_frames);
    consecutive_tx_failures_ = 0;
    backoff_ticks_ = 0;
    return {true, e.clipped};
  }
  const bool queue_full = rc == -ENOBUFS || rc == -EAGAIN;
  bump(queue_full ? n_.tx_queue_full : n_.tx_errors);
  // A full queue may be a burst: tolerated twice. Anything else (the link has gone, the interface is
  // down) is a fault at once.
  if (++consecutive_tx_failures_ >= kTxFailuresToFault || !queue_full) {
    enter_backoff(tick);
    return {false, e.clipped};
  }
  return {true, e.clipped};  // one dropped command: the amplifier holds the last one
}

std::uint64_t CanDriver::flush() noexcept {
  std::uint64_t n = 0;
  canfd_frame f{};
  std::int64_t ts = 0;
  while (channel_.receive(f, ts) > 0) ++n;
  return n;
}

CanCounters CanDriver::counters() const noexcept {
  auto l = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  return {l(n_.rx_frames),     l(n_.rx_other),   l(n_.rx_malformed),   l(n_.lost_frames), l(n_.stale_frames),
          l(n_.error_frames),  l(n_.bus_off),    l(n_.restarts),       l(n_.rx_errors),   l(n_.tx_frames),
          l(n_.tx_queue_full), l(n_.tx_errors),  l(n_.tx_skipped),     l(n_.tx_clipped),  l(n_.rx_held),
          l(n_.rx_skipped),    l(n_.reconnects), l(n_.resync_backoffs)};
}

}  // namespace robodamp::drivers
