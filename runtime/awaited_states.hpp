// The states a pose-scheduled cell's machining monitor waits on (runtime/machining_monitor.hpp): each state the
// robot met (pose grid point, speed, set, K) whose limits were not ready, with when it was met and when last seen
// there. At most a capacity: past it the state the robot stayed in least goes (the first of equals: the oldest),
// so a dwell outlasts the poses a move passes through (on a slow machine, or a virtual clock faster than the
// wall's, a move meets more new states than are kept before the worker has the dwell's limits). Not
// thread-safe: the monitor guards it. Off the real-time path.
#pragma once

#include <cstddef>
#include <vector>

#include "milling/live_stability.hpp"

namespace robodamp::runtime {

// The same state: set, K, speed and pose grid point.
[[nodiscard]] bool same_state(const milling::LiveStability::SweepPoint& a, const milling::LiveStability::SweepPoint& b);

struct AwaitedState {
  double met_s{0.0}, last_s{0.0};  // when the robot met the state, and when it was last seen in it
  milling::LiveStability::SweepPoint point;
};

// `point` seen at time_s: an awaited state's last time, or a new one (the shortest stay dropped first when
// `states` already holds `capacity`).
void await_state(std::vector<AwaitedState>& states, std::size_t capacity, double time_s,
                 milling::LiveStability::SweepPoint point);

}  // namespace robodamp::runtime
