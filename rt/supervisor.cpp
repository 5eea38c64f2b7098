#include "rt/supervisor.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>

namespace robodamp::rt {

namespace {
// A block's RMS this many times the block's before: a blow (a hammer, a tool's entry), not a growing oscillation.
// A loop 1.25 x over its stable gain grows about 1.2 x a block of 0.1 s; the default job's chatter at 2 x its
// damped limit about 1.3 x.
constexpr double kImpulseJump = 3.0;
}  // namespace

Supervisor::Supervisor(const SupervisorSettings& s, const control::ControllerParams& params)
    : s_(s), controller_(params), pose_known_(!s.pose_scheduled) {
  sets_.push_back({params, s.analysis_stable, s.max_stable_gain_ns_per_m, s.delay_margin_s});
  sets_.back().params.set_index = 0;
  speed_refused_set_ = 1;
  const auto window = static_cast<std::size_t>(std::max(1.0, std::round(s.limits.saturation_window_s * s.fs_hz)));
  sat_window_.assign(window, 0);
  sat_threshold_ = static_cast<std::uint64_t>(std::floor(s.limits.saturation_duty_max * static_cast<double>(window)));
  block_len_ = static_cast<std::uint64_t>(std::max(1.0, std::round(s.limits.instability_block_s * s.fs_hz)));
  for (const Trip t : s.limits.recovery.recoverable) recoverable_mask_ |= 1U << static_cast<unsigned>(t);
  recovery_times_.assign(static_cast<std::size_t>(std::max(0, s.limits.recovery.max_recoveries)), -1e300);
}

void Supervisor::log_event(EventKind k, Trip t) noexcept {
  if (events_total_ < kEventLogSize) events_[events_total_] = {time_s_, k, t};
  ++events_total_;
}

std::size_t Supervisor::add_parameter_set(const ParameterSet& set) {
  sets_.push_back(set);
  sets_.back().params.set_index = sets_.size() - 1;
  speed_refused_set_ = sets_.size();
  return sets_.size() - 1;
}

bool Supervisor::select(double i, bool fade_first) noexcept {
  if (!set_index_ok(i)) {
    ++counters_.params_refused;
    return false;
  }
  const auto idx = static_cast<std::size_t>(i);
  const ParameterSet& set = sets_[idx];
  if (idx == active_parameter_set() || !set.analysis_stable || controller_.handover_pending() ||
      set.params.gain_ns_per_m > s_.limits.max_gain_fraction * set.max_stable_gain_ns_per_m ||
      controller_.request_params(set.params, fade_first) != control::RequestStatus::kAccepted) {
    ++counters_.params_refused;
    return false;
  }
  active_set_.store(idx, std::memory_order_relaxed);
  ++counters_.params_selected;
  return true;
}

void Supervisor::set_pose_region(double value) noexcept {
  if (!s_.pose_scheduled || !set_index_ok(value)) {  // out of the map, unknown, or not a set: no analysed set applies
    ++counters_.pose_out_of_map;
    pose_known_ = false;
    if (driving()) trip(Trip::kPoseOutOfMap);
    return;
  }
  ++counters_.pose_regions;
  pose_known_ = true;
  pose_set_ = static_cast<std::size_t>(value);
}

void Supervisor::follow_pose() noexcept {
  if (!s_.pose_scheduled || !pose_known_ || pose_set_ == active_parameter_set() || controller_.handover_pending())
    return;
  if (!select(static_cast<double>(pose_set_))) {  // the region's set refused (cannot pass the configuration's analysis)
    pose_known_ = false;
    if (driving()) trip(Trip::kPoseOutOfMap);
  }
}

// A speed schedule's band on another set: hand over to it once the controller can (its K comes with it). A
// set refused (cannot pass the configuration's analysis, which the cell checked at configuration) leaves
// K at 0 there, the open loop, rather than run the wrong chain at the band's gain; it is not asked again
// until the band's set changes.
void Supervisor::follow_speed() noexcept {
  const control::ControllerParams& p = controller_.params();
  if (!p.speed_scheduled() || controller_.handover_pending()) return;
  const std::size_t want = p.scheduled_set(controller_.schedule_rpm());
  if (want == active_parameter_set() || want == speed_refused_set_) return;
  if (select(static_cast<double>(want), true)) {
    ++counters_.speed_handovers;
    speed_refused_set_ = sets_.size();
  } else {
    ++counters_.speed_handovers_refused;
    speed_refused_set_ = want;
    controller_.ramp_gain_to(0.0);
  }
}

void Supervisor::count_hold(bool held) noexcept {
  if (!held) {
    hold_run_ = 0;
    return;
  }
  if (hold_run_++ == 0) ++counters_.sensor_holds;
  ++counters_.sensor_hold_ticks;
  counters_.longest_sensor_hold_ticks = std::max(counters_.longest_sensor_hold_ticks, hold_run_);
}

void Supervisor::reset_detectors() noexcept {
  std::fill(sat_window_.begin(), sat_window_.end(), std::uint8_t{0});
  sat_pos_ = 0;
  sat_count_ = 0;
  block_ticks_ = 0;
  block_sum_sq_ = block_accel_sum_sq_ = 0.0;
  last_block_rms_ = run_start_rms_ = 0.0;
  growth_run_ = 0;
  block_history_.fill(0.0);
  reset_derate();
}

void Supervisor::trip(Trip t) noexcept {
  ++counters_.trips[static_cast<std::size_t>(t)];
  log_event(EventKind::kTrip, t);
  const bool recoverable = (recoverable_mask_ >> static_cast<unsigned>(t)) & 1U;
  const bool on_probation = time_s_ < probation_until_s_;
  latched_ = !recoverable || on_probation;
  if (recoverable && on_probation) {  // the recovery did not hold
    ++counters_.probation_latches;
    log_event(EventKind::kLatched, t);
  }
  fault_safe_s_ = healthy_s_ = 0.0;
  state_ = State::kFault;
  trip_ = t;
  // On a tick whose sample is stale or invalid nothing is driven, the trip's ramp included: it starts
  // from zero, and the amplifier goes off at once (so too after a stale run that was ridden through).
  trip_from_v_ = hold_now_ ? 0.0 : command_v_;
  trip_ramp_left_s_ = trip_from_v_ != 0.0 ? s_.limits.trip_ramp_s : 0.0;
}

ArmRefusal Supervisor::arm_refusal(bool live) const noexcept {
  if (!live) return ArmRefusal::kSensorNotLive;
  if (!path_ok_) return ArmRefusal::kActuatorPath;
  if (!pose_known_ || (s_.pose_scheduled && (pose_set_ != active_parameter_set() || controller_.handover_pending())))
    return ArmRefusal::kPoseUnknown;
  if (!sets_[active_parameter_set()].analysis_stable || controller_.target_gain_ns_per_m() > max_gain_ns_per_m())
    return ArmRefusal::kAnalysisUnstable;
  return ArmRefusal::kNone;
}

void Supervisor::recover(const TickInput& in) noexcept {
  const RecoverySettings& r = s_.limits.recovery;
  fault_safe_s_ += in.dt_s;
  const auto& l = s_.limits;
  // Healthy: none of the sensor's trip conditions building up (a lone repeated sample, which a CAN
  // de-jitter makes now and then, is not one), ticks on time (no run of consecutive overruns as long as
  // half the trip's: a lone late tick on an ordinary PC is not a burst), and everything else arming asks.
  const bool sensor_ok =
      in.sensor_ok && 2 * stale_run_ < static_cast<std::uint64_t>(l.stale_sensor_cycles) + 1 && invalid_run_ == 0;
  const bool on_time = 2 * overrun_run_ < static_cast<std::uint64_t>(l.overrun_cycles);
  const bool healthy = sensor_ok && on_time && !in.shutdown && arm_refusal(true) == ArmRefusal::kNone;
  healthy_s_ = healthy ? healthy_s_ + in.dt_s : 0.0;
  if (!healthy || fault_safe_s_ < r.cool_down_s || healthy_s_ < r.healthy_for_s) return;  // healthy_for_s may be 0
  // Arming itself needs a live sensor (arming_live_cycles fresh valid samples in a row).
  if (live_run_ < static_cast<std::uint64_t>(l.arming_live_cycles)) return;
  // The budget: at most max_recoveries within window_s (the ring holds the last max_recoveries times).
  if (recovery_times_.empty() || recovery_times_[recovery_pos_] > time_s_ - r.window_s) {
    latched_ = true;
    ++counters_.budget_latches;
    log_event(EventKind::kLatched, trip_);
    return;
  }
  recovery_times_[recovery_pos_] = time_s_;
  recovery_pos_ = (recovery_pos_ + 1) % recovery_times_.size();
  ++counters_.recoveries;
  log_event(EventKind::kRecovered, trip_);
  trip_ = Trip::kNone;
  state_ = State::kArming;  // through the arming path: amplifier ready, then the gain fades in
  arming_s_ = 0.0;
  fade_ = 0.0;
  probation_until_s_ = time_s_ + r.probation_s;
}

void Supervisor::handle(const OperatorCommand& c, bool live) noexcept {
  ++counters_.commands;
  switch (c.kind) {
    case CommandKind::kNone:
      break;
    case CommandKind::kArm: {
      refusal_ = state_ != State::kDisabled ? ArmRefusal::kNotDisabled : arm_refusal(live);
      if (refusal_ != ArmRefusal::kNone) {
        ++counters_.arm_refused;
        break;
      }
      state_ = State::kArming;
      arming_s_ = 0.0;
      fade_ = 0.0;
      break;
    }
    case CommandKind::kDisarm:
      if (state_ == State::kFault) latched_ = true;  // the operator wants it off: no automatic recovery
      if (state_ == State::kArming) state_ = State::kDisabled;
      if (state_ == State::kActive) state_ = State::kStopping;
      break;
    case CommandKind::kResetFault:
      if (state_ == State::kFault && trip_ramp_left_s_ <= 0.0) {
        state_ = State::kDisabled;
        trip_ = Trip::kNone;
      }
      break;
    case CommandKind::kSetGain:  // inside a speed schedule's band K is the band's (the controller refuses)
      if (!(std::isfinite(c.value) && c.value >= 0.0 && c.value <= max_gain_ns_per_m()) ||
          controller_.set_gain(c.value) != control::RequestStatus::kAccepted)
        ++counters_.gain_refused;
      break;
    case CommandKind::kSelectParams:  // a speed schedule's sets follow the spindle, not requests
      if (controller_.params().speed_chooses_set())
        ++counters_.params_refused;
      else
        (void)select(c.value);
      break;
    case CommandKind::kSetPoseRegion:
      set_pose_region(c.value);
      break;
    case CommandKind::kStartExcitation:
      break;                        // the loop's excitation clock, not a decision of the supervisor
    case CommandKind::kSetSpindle:  // validated by the controller: refused speeds park the notches
      if (controller_.set_spindle_rpm(c.value) != control::RequestStatus::kAccepted) ++counters_.spindle_refused;
      break;
  }
}

Trip Supervisor::check_trips(const TickInput& in) const noexcept {
  if (state_ == State::kFault) return Trip::kNone;  // latched: the first reason stands
  if (in.shutdown) return Trip::kSignal;
  if (state_ == State::kDisabled) return Trip::kNone;  // not driving
  const auto& l = s_.limits;
  if (stale_run_ >= static_cast<std::uint64_t>(l.stale_sensor_cycles)) return Trip::kSensorStale;
  if (invalid_run_ >= static_cast<std::uint64_t>(l.invalid_sample_cycles)) return Trip::kSampleInvalid;
  if (!in.sensor_ok) return Trip::kSensorDriver;
  if (!in.actuator_ok) return Trip::kActuatorDriver;
  if (in.amplifier_fault) return Trip::kAmplifierFault;
  if (overrun_run_ >= static_cast<std::uint64_t>(l.overrun_cycles) && overrun_run_s_ >= overrun_tolerance_s())
    return Trip::kOverruns;
  if (state_ == State::kArming && !in.amplifier_ready && arming_s_ >= l.amplifier_ready_timeout_s)
    return Trip::kAmplifierNotReady;
  return Trip::kNone;
}

bool Supervisor::record_saturation(bool saturated) noexcept {
  sat_count_ -= sat_window_[sat_pos_];
  sat_window_[sat_pos_] = saturated ? 1 : 0;
  sat_count_ += sat_window_[sat_pos_];
  if (++sat_pos_ == sat_window_.size()) sat_pos_ = 0;
  return sat_count_ > sat_threshold_;
}

bool Supervisor::instability(double controller_v, double accel_mps2) noexcept {
  block_sum_sq_ += controller_v * controller_v;
  block_accel_sum_sq_ += accel_mps2 * accel_mps2;
  if (++block_ticks_ < block_len_) return false;
  const double rms = std::sqrt(block_sum_sq_ / static_cast<double>(block_len_));
  const double accel_rms = std::sqrt(block_accel_sum_sq_ / static_cast<double>(block_len_));
  block_ticks_ = 0;
  block_sum_sq_ = block_accel_sum_sq_ = 0.0;
  const auto& l = s_.limits;
  // A run counts from a block within one growth factor of the floor: the growth that matters is the one
  // that carries the command over the floor. Below it, a quiet loop's command beats up and down (a rising
  // envelope for a few blocks is common), and a hammer blow landing at the end of such a rise made a run
  // of ambient blocks plus one struck block look like a growing oscillation.
  const double counted = l.instability_floor_v / l.instability_growth_factor;
  // With the spindle turning a block more than kImpulseJump times the one before is a blow, not a growth: the
  // run starts afresh from it.
  const bool jump = derating_on() && rms > kImpulseJump * last_block_rms_;
  if (last_block_rms_ > 0.0 && rms > last_block_rms_ && last_block_rms_ >= counted && !jump) {
    if (growth_run_ == 0) run_start_rms_ = last_block_rms_;
    ++growth_run_;
  } else {
    growth_run_ = 0;
  }
  last_block_rms_ = rms;
  last_accel_rms_ = accel_rms;
  blocks_since_jump_ = jump ? 0 : blocks_since_jump_ + 1;
  block_history_[block_history_pos_] = rms;
  block_history_pos_ = (block_history_pos_ + 1) % kBlockHistory;
  const bool grown = growth_run_ >= l.instability_blocks && rms >= l.instability_floor_v &&
                     rms >= l.instability_growth_factor * run_start_rms_ &&
                     !(controller_.schedule_rpm() > 0.0 && (building_up() || beating()));
  restore_when_quiet();
  return derating_on() ? judge_growth(rms, accel_rms, grown) : grown;
}

// With the spindle turning, a cut's entry builds up a forced vibration and a cut near its limit beats: the
// tooth-passing response and the slowly decaying free vibration of the chatter mode (the loop's or the cut's,
// near the boundary) add and cancel in turn. At a tooth-passing frequency near a mode the command rises block
// after block for a second or more, and the growth rule alone called that an instability (the default job's
// C2 at K 1380 at 198 rpm, 3 x 9.9 Hz beside the 9.2 Hz mode, a cut at 0.8-0.95 x its limit: the probes
// switched the damping off again and again, and the cut chattered). A loop's instability or a chatter grows
// exponentially, the same ratio block after block, beyond anything before it, until a limit. So:
// - a build-up slows down: over the run's last blocks (at most 16), the later half's growth (in log) under 0.7 x
//   the earlier half's is not a growth;
// - a beat falls back: a run whose RMS is not above every block before it in the history (kBlockHistory blocks
//   before the run) is not a growth.
// A chatter rising out of a build-up or a beat grows faster later and beyond the beat's peaks: it stays one.
bool Supervisor::building_up() const noexcept {
  const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(growth_run_), 16);
  const std::size_t h = n / 2;
  if (h == 0) return false;
  const double earlier = std::log(history_back(n - h) / history_back(n));
  const double later = std::log(history_back(0) / history_back(h));
  return later < 0.7 * earlier;
}

bool Supervisor::beating() const noexcept {
  double before = 0.0;
  for (std::size_t k = static_cast<std::size_t>(growth_run_) + 1; k < kBlockHistory; ++k)
    before = std::max(before, history_back(k));
  return history_back(0) <= before;
}

TickOutput Supervisor::step(const TickInput& in) noexcept {
  ++counters_.ticks;
  time_s_ += in.dt_s;
  const bool valid = assess_sample(in);
  const ControlStep c = run_controller(in, valid);
  // Operator commands at the tick boundary, then the trips (which override them).
  if (in.command.kind != CommandKind::kNone)
    handle(in.command, live_run_ >= static_cast<std::uint64_t>(s_.limits.arming_live_cycles));
  follow_pose();
  follow_speed();
  if (const Trip t = check_trips(in); t != Trip::kNone) trip(t);
  TickOutput out;
  out.controller_v = c.controller_v;
  out.filtered_mps = controller_.filtered_mps();
  drive(in, c, out);
  if (state_ == State::kFault) ramp_down_fault(in, out);
  count_hold(c.hold && (state_ == State::kActive || state_ == State::kStopping));
  out.command_v = command_v_;
  out.state = state_;
  out.trip = trip_;
  observed_state_.store(state_, std::memory_order_relaxed);
  observed_trip_.store(trip_, std::memory_order_relaxed);
  running_set_.store(controller_.params().set_index, std::memory_order_relaxed);
  return out;
}

// The sample's health: a repeat (not fresh) is stale; a fresh one must be finite and in range. Also the
// runs the trips and the arming read (stale, invalid, live, overrun) and the path's health.
bool Supervisor::assess_sample(const TickInput& in) noexcept {
  const bool valid = std::isfinite(in.accel_mps2) && std::abs(in.accel_mps2) <= s_.sample_limit_mps2;
  if (!in.fresh) {
    ++stale_run_;
    ++counters_.stale_ticks;
  } else {
    stale_run_ = 0;
    if (valid) {
      invalid_run_ = 0;
    } else {
      ++invalid_run_;
      ++counters_.invalid_samples;
    }
  }
  live_run_ = in.fresh && valid && in.sensor_ok ? live_run_ + 1 : 0;
  if (in.overrun) {
    ++overrun_run_;
    overrun_run_s_ += in.dt_s;
    ++counters_.overruns;
  } else {
    if (overrun_run_ >= static_cast<std::uint64_t>(s_.limits.overrun_cycles) && trip_ != Trip::kOverruns)
      ++counters_.overrun_runs_ridden;
    overrun_run_ = 0;
    overrun_run_s_ = 0.0;
  }
  path_ok_ = in.sensor_ok && in.actuator_ok && !in.amplifier_fault;
  return valid;
}

// The controller runs in every state so its filters are settled when it is armed. It only ever sees
// valid samples. On a stale or invalid one it is fed no acceleration (its velocity estimate holds rather
// than integrating a repeated sample), and its output does not reach the actuator this tick.
Supervisor::ControlStep Supervisor::run_controller(const TickInput& in, bool valid) noexcept {
  const bool sample_ok = in.fresh && valid;
  ControlStep c;
  c.hold = !sample_ok && s_.limits.zero_command_while_stale;
  hold_now_ = c.hold;
  if (sample_ok) last_valid_mps2_ = in.accel_mps2;
  c.controller_v = controller_.update(c.hold ? 0.0 : last_valid_mps2_);
  c.driving_v = c.hold ? 0.0 : c.controller_v;
  const control::ControllerCounters& cc = controller_.counters();
  c.limited = cc.force_limited != last_limits_.force_limited || cc.voltage_limited != last_limits_.voltage_limited ||
              cc.slew_limited != last_limits_.slew_limited;
  last_limits_ = cc;
  return c;
}

// The command in each state: nothing while disabled or arming (arming asks for the amplifier and
// activates when it is ready), the faded controller (with the loop's excitation added) while active,
// where the saturation duty and the instability detector can trip, and the fade-out while stopping.
void Supervisor::drive(const TickInput& in, const ControlStep& c, TickOutput& out) noexcept {
  switch (state_) {
    case State::kDisabled:
      command_v_ = 0.0;
      break;
    case State::kArming:
      command_v_ = 0.0;
      out.amplifier_enable = true;
      arming_s_ += in.dt_s;
      if (in.amplifier_ready) {
        state_ = State::kActive;
        fade_ = 0.0;
        reset_detectors();
      }
      break;
    case State::kActive: {
      fade_ = s_.fade_s > 0.0 ? std::min(1.0, fade_ + in.dt_s / s_.fade_s) : 1.0;
      command_v_ = fade_ * c.driving_v;
      bool clamped = false;  // the test signal and the controller together beyond the amplifier's limit
      if (in.excitation_v != 0.0) {
        const double lim = s_.command_limit_v;
        const double sum_v = fade_ * (c.driving_v + in.excitation_v);
        command_v_ = std::clamp(sum_v, -lim, lim);
        clamped = command_v_ != sum_v;
      }
      out.amplifier_enable = true;
      out.saturated = c.limited || in.actuator_saturated || clamped;
      if (out.saturated) ++counters_.saturated_ticks;
      out.derated = controller_.derate() < 1.0;
      if (out.derated) ++counters_.derated_ticks;
      if (record_saturation(out.saturated)) {
        if (!saturated_while_turning()) trip(Trip::kSaturation);
      } else if (instability(growth_signal_v(c.controller_v), last_valid_mps2_)) {
        trip(Trip::kInstability);
      }
      if (state_ == State::kFault) command_v_ = trip_from_v_;  // the ramp starts from the last command
      break;
    }
    case State::kStopping:
      fade_ = s_.fade_s > 0.0 ? fade_ - in.dt_s / s_.fade_s : 0.0;
      if (fade_ <= 0.0) {
        fade_ = 0.0;
        state_ = State::kDisabled;
        command_v_ = 0.0;
      } else {
        command_v_ = fade_ * c.driving_v;
        out.amplifier_enable = true;
      }
      break;
    case State::kFault:
      break;
  }
}

// A trip: a linear ramp from the command at the trip to zero over trip_ramp_s (measured time), then the
// amplifier off and, unless latched, recovery (re-arming from the next tick on, state kArming).
void Supervisor::ramp_down_fault(const TickInput& in, TickOutput& out) noexcept {
  const auto& l = s_.limits;
  if (trip_ramp_left_s_ > 0.0) trip_ramp_left_s_ -= in.dt_s;
  if (trip_ramp_left_s_ > 0.0 && l.trip_ramp_s > 0.0) {
    command_v_ = trip_from_v_ * (trip_ramp_left_s_ / l.trip_ramp_s);
    out.amplifier_enable = true;
  } else {
    trip_ramp_left_s_ = 0.0;
    command_v_ = 0.0;
    out.amplifier_enable = false;
    if (!latched_) recover(in);
  }
}

}  // namespace robodamp::rt
