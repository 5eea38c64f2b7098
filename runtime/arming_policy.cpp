#include "runtime/arming_policy.hpp"

#include <algorithm>
#include <cmath>

namespace robodamp::runtime {

ArmingSchedule ArmingSchedule::from(const config::SupervisionConfig& s, double rate_hz) {
  ArmingSchedule a;
  a.first_tick = static_cast<std::uint64_t>(s.arming_live_cycles) + 1;
  a.retry_ticks = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(s.arm_retry_s * rate_hz)));
  a.deadline_tick = a.first_tick + static_cast<std::uint64_t>(std::llround(s.arm_deadline_s * rate_hz));
  return a;
}

const char* to_string(ArmingOutcome o) {
  switch (o) {
    case ArmingOutcome::kWaiting:
      return "waiting";
    case ArmingOutcome::kArmed:
      return "armed";
    case ArmingOutcome::kFaulted:
      return "faulted";
    case ArmingOutcome::kGaveUp:
      return "gave_up";
    case ArmingOutcome::kCancelled:
      return "cancelled";
  }
  return "?";
}

void ArmingPolicy::finish(ArmingOutcome o) noexcept {
  auto expected = ArmingOutcome::kWaiting;
  (void)outcome_.compare_exchange_strong(expected, o, std::memory_order_acq_rel);
}

void ArmingPolicy::cancel() noexcept { finish(ArmingOutcome::kCancelled); }

rt::PolicyDecision ArmingPolicy::on_tick(std::uint64_t tick, rt::State state, rt::ArmRefusal refusal) noexcept {
  if (outcome_.load(std::memory_order_relaxed) != ArmingOutcome::kWaiting) return {};
  if (attempts_.load(std::memory_order_relaxed) > 0 && refusal != rt::ArmRefusal::kNone)
    refusal_.store(refusal, std::memory_order_relaxed);
  switch (state) {
    case rt::State::kActive:
      finish(ArmingOutcome::kArmed);
      return {};
    case rt::State::kFault:
      finish(ArmingOutcome::kFaulted);
      return {};
    case rt::State::kArming:
    case rt::State::kStopping:
      return {};  // an attempt is under way, or a fade-out to finish first
    case rt::State::kDisabled:
      break;
  }
  if (tick >= s_.deadline_tick) {
    finish(ArmingOutcome::kGaveUp);
    return {{}, true};
  }
  if (tick < next_tick_) return {};
  next_tick_ = tick + s_.retry_ticks;
  attempts_.fetch_add(1, std::memory_order_relaxed);
  return {{rt::CommandKind::kArm, 0.0}, false};
}

}  // namespace robodamp::runtime
