// The arming policy, the same for every backend (simulated plant, CAN + Modbus, the HIL emulator): arm
// at the first tick the sensor can be live (supervision.arming_live_cycles + 1), retry every
// supervision.arm_retry_s while the supervisor stays disabled, and give up after
// supervision.arm_deadline_s of loop time, ending the run: `robodamp run` then exits non-zero naming
// the last refusal (apps/run_command.cpp). Once the loop has been active, or a trip has latched, or an
// operator has taken over (cancel()), it issues nothing more: a trip is reset only by an operator, and
// the end of a run is never re-armed.
//
// It runs on the loop thread through rt::TickPolicy, so a virtual-clock run is deterministic and its
// recording replays the arm commands like any other. on_tick() is RT-safe; the outcome is readable from
// any thread (atomics).
#pragma once

#include <atomic>
#include <cstdint>

#include "config/config.hpp"
#include "rt/tick_policy.hpp"

namespace robodamp::runtime {

struct ArmingSchedule {
  std::uint64_t first_tick{51};
  std::uint64_t retry_ticks{2500};
  std::uint64_t deadline_tick{50000};  // loop ticks since the start of the run

  // From the supervision section at the loop rate (arm_retry_s, arm_deadline_s, arming_live_cycles).
  [[nodiscard]] static ArmingSchedule from(const config::SupervisionConfig& s, double rate_hz);
};

enum class ArmingOutcome : std::uint8_t {
  kWaiting,    // still trying
  kArmed,      // the loop became active
  kFaulted,    // a trip latched before the loop was ever active (the trip says why)
  kGaveUp,     // the deadline passed with every attempt refused (last_refusal says why)
  kCancelled,  // an operator armed or disarmed (DDS request)
};
[[nodiscard]] const char* to_string(ArmingOutcome o);

class ArmingPolicy final : public rt::TickPolicy {
 public:
  explicit ArmingPolicy(const ArmingSchedule& s) noexcept : s_(s), next_tick_(s.first_tick) {}

  [[nodiscard]] rt::PolicyDecision on_tick(std::uint64_t tick, rt::State state,
                                           rt::ArmRefusal refusal) noexcept override;
  // From any thread: an operator took over arming.
  void cancel() noexcept;

  [[nodiscard]] ArmingOutcome outcome() const noexcept { return outcome_.load(std::memory_order_acquire); }
  [[nodiscard]] std::uint32_t attempts() const noexcept { return attempts_.load(std::memory_order_relaxed); }
  // The supervisor's reason for the last refused attempt (kNone if none was refused).
  [[nodiscard]] rt::ArmRefusal last_refusal() const noexcept { return refusal_.load(std::memory_order_relaxed); }
  [[nodiscard]] const ArmingSchedule& schedule() const noexcept { return s_; }

 private:
  void finish(ArmingOutcome o) noexcept;

  ArmingSchedule s_;
  std::uint64_t next_tick_;
  std::atomic<ArmingOutcome> outcome_{ArmingOutcome::kWaiting};
  std::atomic<std::uint32_t> attempts_{0};
  std::atomic<rt::ArmRefusal> refusal_{rt::ArmRefusal::kNone};
};

}  // namespace robodamp::runtime
