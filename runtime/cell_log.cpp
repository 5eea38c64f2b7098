// The cell's log of what the loop does, as it happens (docs/runtime.md): on the drain thread, off the RT path.
#include <spdlog/spdlog.h>

#include "rt/supervisor.hpp"
#include "rt/telemetry_frame.hpp"
#include "runtime/cell.hpp"

namespace robodamp::runtime {

// On the drain thread (off the real-time path): a trip, a state change and the derating are logged when they
// happen, not only in the summary at the run's end.
void Cell::log_changes(const rt::TelemetryFrame& f) {
  if (f.trip != seen_trip_ && f.trip != 0) {
    const auto t = static_cast<rt::Trip>(f.trip);
    spdlog::warn("loop: tripped {} at {:.3f} s: {}", rt::to_string(t), f.time_s, rt::describe(t));
  }
  if (f.state != seen_state_ && seen_state_ != 255)
    spdlog::info("loop: {} at {:.3f} s", rt::to_string(static_cast<rt::State>(f.state)), f.time_s);
  if (const bool derated = (f.flags & rt::kFlagDerated) != 0; derated && !seen_derated_)
    spdlog::info("loop: derated at {:.3f} s (the cut's growth or the actuator's saturation: supervision.derate)",
                 f.time_s);
  else if (!derated && seen_derated_)
    spdlog::info("loop: back to full gain at {:.3f} s", f.time_s);
  seen_trip_ = f.trip;
  seen_state_ = f.state;
  seen_derated_ = (f.flags & rt::kFlagDerated) != 0;
}

}  // namespace robodamp::runtime
