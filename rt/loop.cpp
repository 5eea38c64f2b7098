#include "rt/loop.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "rt/signals.hpp"

namespace robodamp::rt {

namespace {
std::uint32_t sat32(std::uint64_t v) noexcept {
  return v > 0xFFFFFFFFULL ? 0xFFFFFFFFU : static_cast<std::uint32_t>(v);
}
}  // namespace

Loop::Loop(double rate_hz, ClockKind clock, Supervisor& supervisor, SensorSource& sensor, ActuatorSink& actuator,
           AmplifierIo& io, SpscRing<TelemetryFrame>* telemetry)
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
  const double period_s = static_cast<double>(period_ns_) * 1e-9;
  const std::int64_t t0 = monotonic_ns();
  if (tick_ == 0) st.start_monotonic_ns = t0;
  // Enough ticks after the end for the slowest ramp to finish; after that the loop returns regardless.
  const auto tail_ticks = static_cast<std::uint64_t>(
      std::ceil((sup_.settings().fade_s + sup_.settings().limits.trip_ramp_s + 1.0) / period_s));
  Run r{DeadlinePacer(period_ns_, t0), tick_ + duration_ticks, tail_ticks, t0 - period_ns_};
  while (true) {
    const Pace p = pace(r);
    TickInput in = inputs(r, p);
    in.command = next_command(r);
    if (in.command.kind == CommandKind::kStartExcitation) excitation_.start_next_tick();
    const TickOutput out = sup_.step(in);
    r.actuator = actuator_.write(out.command_v, tick_);
    io_.request_amplifier_enable(out.amplifier_enable);
    account(r, p, in);
    publish(p, in, out);
    if (in.shutdown || r.ending) {
      if (sup_.safe() || ++r.ending_ticks > r.tail_ticks) break;
    }
    ++tick_;
    r.pacer.advance();
  }
  st.elapsed_s = static_cast<double>(monotonic_ns() - t0) * 1e-9;
}

// Wall clock: sleep to the deadline, skip whole periods missed (never a burst); virtual: no wait.
Loop::Pace Loop::pace(Run& r) noexcept {
  Pace p;
  if (clock_ == ClockKind::kWall) {
    const DeadlinePacer::Wake w = r.pacer.wait();
    p.wake_ns = w.wake_ns, p.latency_ns = w.late_ns, p.missed = w.missed;
    tick_ += w.missed;
    stats_->missed_ticks += w.missed;
    p.dt_s = static_cast<double>(p.wake_ns - r.prev_wake_ns) * 1e-9;
  } else {
    p.wake_ns = monotonic_ns();
    p.dt_s = static_cast<double>(period_ns_) * 1e-9;
  }
  r.prev_wake_ns = p.wake_ns;
  return p;
}

// The sensor and the devices' health as the supervisor sees them this tick.
TickInput Loop::inputs(const Run& r, const Pace& p) noexcept {
  const SensorSample sample = sensor_.read(tick_);
  const AmplifierStatus amp = io_.amplifier_status();
  TickInput in;
  in.dt_s = p.dt_s;
  in.accel_mps2 = sample.accel_mps2;
  in.fresh = sample.fresh;
  in.sensor_ok = sample.ok;
  in.actuator_ok = r.actuator.ok && !amp.link_lost;  // a lost supervisory link: the command's path is not known
  in.actuator_saturated = r.actuator.saturated;
  in.amplifier_ready = amp.ready;
  in.amplifier_fault = amp.fault;
  in.overrun = r.overrun || p.missed > 0;
  in.shutdown = shutdown_ != nullptr && shutdown_->load(std::memory_order_relaxed) != 0;
  in.excitation_v = excitation_.next_v(p.dt_s);
  return in;
}

// The end of the run, a scheduled command, the tick policy's, then one posted by another thread.
OperatorCommand Loop::next_command(Run& r) noexcept {
  const bool scripted = next_scheduled_ < scheduled_.size() && scheduled_[next_scheduled_].first <= tick_;
  PolicyDecision policy{};
  if (policy_ != nullptr && !r.ending && !scripted)
    policy = policy_->on_tick(tick_, sup_.state(), sup_.last_arm_refusal());
  if (!r.ending && (tick_ >= r.end_tick || policy.end_run || stop_.load(std::memory_order_relaxed))) {
    r.ending = true;
    return {CommandKind::kDisarm, 0.0};
  }
  if (scripted) return scheduled_[next_scheduled_++].second;
  if (policy.command.kind != CommandKind::kNone) return policy.command;
  OperatorCommand c{};
  if (!commands_.pop(c)) c = {};
  return c;
}

// The tick's timing: compute time, overruns (late wake-up or work past the next deadline).
void Loop::account(Run& r, const Pace& p, const TickInput& in) noexcept {
  LoopStats& st = *stats_;
  const bool wall = clock_ == ClockKind::kWall;
  const std::int64_t end = monotonic_ns();
  const std::int64_t compute = end - p.wake_ns;
  r.overrun = wall && end > r.pacer.deadline_ns() + period_ns_;
  if (in.overrun) ++st.overruns;
  if (wall) st.wake_latency.record(p.latency_ns);
  st.compute.record(compute);
  ++st.ticks_run;
  st.last_tick = tick_;
  last_compute_ns_ = compute;
}

// The telemetry frame. Wall clock: a full ring drops the frame (counted); virtual clock: the loop waits
// for the drain rather than lose one, and waits as soon as it is kVirtualLeadFrames ahead of it. On the
// virtual clock the loop runs as fast as the CPU lets it, and the drain's consumers (the recorder, the
// safety watches of commissioning and measurement, which stop the cell) would otherwise see each frame as
// late as the ring is long (65 536 frames, 13 s of loop time at 5 kHz) whenever the drain thread is not
// scheduled for a while: on a loaded machine a measurement's chirp played 8 s on before the watch that
// refused it could stop it. The wall clock keeps that lag to the drain's poll on a real cell.
void Loop::publish(const Pace& p, const TickInput& in, const TickOutput& out) noexcept {
  if (telemetry_ == nullptr) return;
  LoopStats& st = *stats_;
  const bool wall = clock_ == ClockKind::kWall;
  const SupervisorCounters& sc = sup_.counters();
  TelemetryFrame f;
  f.tick = tick_;
  f.time_s = static_cast<double>(tick_) * period_s();
  f.dt_s = p.dt_s;
  f.accel_mps2 = in.accel_mps2;
  f.filtered_mps = out.filtered_mps;
  f.controller_v = out.controller_v;
  f.command_v = out.command_v;
  f.gain_ns_per_m = sup_.controller().gain_ns_per_m();
  f.command_value = in.command.value;
  f.wake_latency_us = wall ? static_cast<float>(static_cast<double>(p.latency_ns) * 1e-3) : 0.0F;
  f.compute_us = wall ? static_cast<float>(static_cast<double>(last_compute_ns_) * 1e-3) : 0.0F;
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
      (out.saturated ? kFlagSaturated : 0) | (out.derated ? kFlagDerated : 0));
  f.state = static_cast<std::uint8_t>(out.state);
  f.trip = static_cast<std::uint8_t>(out.trip);
  f.command_kind = static_cast<std::uint8_t>(in.command.kind);
  if (wall) {
    if (!telemetry_->push(f)) ++st.ring_drops;
    return;
  }
  while (telemetry_->size() >= kVirtualLeadFrames || !telemetry_->push(f)) {
    ++st.ring_waits;
    std::this_thread::yield();
  }
}

}  // namespace robodamp::rt
