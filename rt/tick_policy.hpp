// A policy the loop consults once per tick, on the real-time thread, when no scripted command is due:
// it may issue one operator command (the arming policy arms and retries) and may end the run (it gave
// up). It sees only the supervisor's state after the previous tick, so a virtual-clock run stays
// deterministic and a recording replays its commands like any other. Implementations are RT-safe:
// noexcept, no allocation, locking, I/O or logging (runtime/arming_policy.hpp is the one robodamp has).
#pragma once

#include <cstdint>

#include "rt/supervisor.hpp"

namespace robodamp::rt {

struct PolicyDecision {
  OperatorCommand command{};  // kNone: nothing this tick
  bool end_run{false};        // end the run as if its duration were over (disarm, ramp, return)
};

class TickPolicy {
 public:
  virtual ~TickPolicy() = default;
  // RT-safe. `state` and `refusal` are the supervisor's after the previous tick.
  [[nodiscard]] virtual PolicyDecision on_tick(std::uint64_t tick, State state, ArmRefusal refusal) noexcept = 0;
};

}  // namespace robodamp::rt
