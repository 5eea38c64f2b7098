#include "rt/loop.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "rt/signals.hpp"

namespace robodamp::rt {

namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;

std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void sleep_until(std::int64_t t_ns) noexcept {
  timespec ts{static_cast<time_t>(t_ns / kNsPerS), static_cast<long>(t_ns % kNsPerS)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

std::uint32_t sat32(std::uint64_t v) noexcept { return v > 0xFFFFFFFFULL ? 0xFFFFFFFFU : static_cast<std::uint32_t>(v); }
}  // namespace

Loop::Loop(double rate_hz, config::ClockKind clock, Supervisor& supervisor, SensorSource& sensor,
           ActuatorSink& actuator, SupervisoryIo& io, SpscRing<TelemetryFrame>* telemetry)
    : period_ns_(static_cast<std::int64_t>(std::llround(1e9 / rate_hz))),
      clock_(clock),
      sup_(supervisor),
      sensor_(sensor),
      actuator_(actuator),
      io_(io),
      telemetry_(telemetry),
      shutdown_(&shutdown_signal()),
      stats_(std::make_unique<LoopStats>()) {}

void Loop::schedule(std::uint64_t tick, const OperatorCommand& c) {
  scheduled_.emplace_back(tick, c);
  std::stable_sort(scheduled_.begin() + static_cast<std::ptrdiff_t>(next_scheduled_), scheduled_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
}

void Loop::run(std::uint64_t duration_ticks) noexcept {
  LoopStats& st = *stats_;
  const bool wall = clock_ == config::ClockKind::kWall;
  const double period_s = static_cast<double>(period_ns_) * 1e-9;
  const std::uint64_t end_tick = tick_ + duration_ticks;
  // Enough ticks after the end for the slowest ramp to finish; after that the loop returns regardless.
  const auto tail_ticks = static_cast<std::uint64_t>(
      std::ceil((sup_.settings().fade_s + sup_.settings().limits.trip_ramp_s + 1.0) / period_s));
  const std::int64_t t0 = now_ns();
  std::int64_t deadline = t0;
  if (tick_ == 0) st.start_monotonic_ns = t0;
  std::int64_t prev_wake = t0 - period_ns_;
  ActuatorStatus act{};
  bool overrun = false;
  bool ending = false;
  std::uint64_t ending_ticks = 0;

  while (true) {
    std::int64_t wake, latency = 0;
    std::uint64_t missed = 0;
    if (wall) {
      sleep_until(deadline);
      wake = now_ns();
      latency = wake - deadline;
      if (latency >= period_ns_) {  // skip what was missed, never burst
        missed = static_cast<std::uint64_t>(latency / period_ns_);
        deadline += static_cast<std::int64_t>(missed) * period_ns_;
        tick_ += missed;
        st.missed_ticks += missed;
      }
    } else {
      wake = now_ns();
    }
    const double dt_s = wall ? static_cast<double>(wake - prev_wake) * 1e-9 : period_s;
    prev_wake = wake;

    const SensorSample sample = sensor_.read(tick_);
    const AmplifierStatus amp = io_.amplifier_status();
    TickInput in;
    in.dt_s = dt_s;
    in.accel_mps2 = sample.accel_mps2;
    in.fresh = sample.fresh;
    in.sensor_ok = sample.ok;
    in.actuator_ok = act.ok && !amp.link_lost;  // a lost supervisory link: the command's path is not known
    in.actuator_saturated = act.saturated;
    in.amplifier_ready = amp.ready;
    in.amplifier_fault = amp.fault;
    in.overrun = overrun || missed > 0;
    in.shutdown = shutdown_ != nullptr && shutdown_->load(std::memory_order_relaxed) != 0;
    const bool scripted = next_scheduled_ < scheduled_.size() && scheduled_[next_scheduled_].first <= tick_;
    PolicyDecision policy{};
    if (policy_ != nullptr && !ending && !scripted) policy = policy_->on_tick(tick_, sup_.state(), sup_.last_arm_refusal());
    if (!ending && (tick_ >= end_tick || policy.end_run || stop_.load(std::memory_order_relaxed))) {
      ending = true;
      in.command = {CommandKind::kDisarm, 0.0};
    } else if (scripted) {
      in.command = scheduled_[next_scheduled_++].second;
    } else if (policy.command.kind != CommandKind::kNone) {
      in.command = policy.command;
    } else if (!commands_.pop(in.command)) {
      in.command = {};
    }

    const TickOutput out = sup_.step(in);
    act = actuator_.write(out.command_v, tick_);
    io_.request_amplifier_enable(out.amplifier_enable);

    const std::int64_t end = now_ns();
    const std::int64_t compute = end - wake;
    overrun = wall && end > deadline + period_ns_;
    if (in.overrun) ++st.overruns;
    if (wall) st.wake_latency.record(latency);
    st.compute.record(compute);
    ++st.ticks_run;
    st.last_tick = tick_;

    if (telemetry_ != nullptr) {
      const SupervisorCounters& sc = sup_.counters();
      TelemetryFrame f;
      f.tick = tick_;
      f.time_s = static_cast<double>(tick_) * period_s;
      f.dt_s = dt_s;
      f.accel_mps2 = in.accel_mps2;
      f.filtered_mps = out.filtered_mps;
      f.controller_v = out.controller_v;
      f.command_v = out.command_v;
      f.gain_ns_per_m = sup_.controller().gain_ns_per_m();
      f.command_value = in.command.value;
      f.wake_latency_us = wall ? static_cast<float>(static_cast<double>(latency) * 1e-3) : 0.0F;
      f.compute_us = wall ? static_cast<float>(static_cast<double>(compute) * 1e-3) : 0.0F;
      f.missed_ticks = sat32(st.missed_ticks);
      f.overruns = sat32(st.overruns);
      f.saturated_ticks = sat32(sc.saturated_ticks);
      f.ring_drops = sat32(st.ring_drops);
      f.stale_ticks = sat32(sc.stale_ticks);
      f.invalid_samples = sat32(sc.invalid_samples);
      f.flags = static_cast<std::uint16_t>(
          (in.fresh ? kFlagFresh : 0) | (in.sensor_ok ? kFlagSensorOk : 0) | (in.actuator_ok ? kFlagActuatorOk : 0) |
          (in.actuator_saturated ? kFlagActuatorSaturated : 0) | (in.amplifier_ready ? kFlagAmplifierReady : 0) |
          (in.amplifier_fault ? kFlagAmplifierFault : 0) | (in.overrun ? kFlagOverrun : 0) |
          (in.shutdown ? kFlagShutdown : 0) | (out.amplifier_enable ? kFlagAmplifierEnable : 0) |
          (out.saturated ? kFlagSaturated : 0));
      f.state = static_cast<std::uint8_t>(out.state);
      f.trip = static_cast<std::uint8_t>(out.trip);
      f.command_kind = static_cast<std::uint8_t>(in.command.kind);
      if (wall) {
        if (!telemetry_->push(f)) ++st.ring_drops;
      } else {
        // Virtual time has no deadline: wait for the drain rather than lose a frame.
        while (!telemetry_->push(f)) {
          ++st.ring_waits;
          std::this_thread::yield();
        }
      }
    }

    if (in.shutdown || ending) {
      if (sup_.safe() || ++ending_ticks > tail_ticks) break;
    }
    ++tick_;
    deadline += period_ns_;
  }
  st.elapsed_s = static_cast<double>(now_ns() - t0) * 1e-9;
}

}  // namespace robodamp::rt
