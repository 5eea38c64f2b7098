#include "runtime/awaited_states.hpp"

#include <algorithm>
#include <utility>

namespace robodamp::runtime {

bool same_state(const milling::LiveStability::SweepPoint& a, const milling::LiveStability::SweepPoint& b) {
  return a.set == b.set && a.gain_ns_per_m == b.gain_ns_per_m && a.rpm == b.rpm && a.pose_deg == b.pose_deg;
}

void await_state(std::vector<AwaitedState>& states, std::size_t capacity, double time_s,
                 milling::LiveStability::SweepPoint point) {
  for (AwaitedState& a : states)
    if (same_state(a.point, point)) {
      a.last_s = time_s;
      return;
    }
  if (capacity == 0) return;
  if (states.size() >= capacity)
    states.erase(std::min_element(states.begin(), states.end(), [](const AwaitedState& x, const AwaitedState& y) {
      return x.last_s - x.met_s < y.last_s - y.met_s;
    }));
  states.push_back({time_s, time_s, std::move(point)});
}

}  // namespace robodamp::runtime
