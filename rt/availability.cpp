#include "rt/availability.hpp"

#include "rt/supervisor.hpp"

namespace robodamp::rt {

void AvailabilityMeter::on_frame(const TelemetryFrame& f) {
  const bool active = f.state == static_cast<std::uint8_t>(State::kActive);
  if (!active)
    active_since_s_ = -1.0;
  else if (active_since_s_ < 0.0)
    active_since_s_ = f.time_s;
  // Full gain: active for a whole gain ramp (the arming's and every re-arm's fade-in is over).
  const bool full = active && f.time_s - active_since_s_ >= ramp_s_ - 0.5 * period_s_;
  if (full && a_.first_full_gain_s < 0.0) a_.first_full_gain_s = f.time_s;
  // Stopping or disabled with no trip: the run's end or an operator asked for off; not asked to damp.
  const bool off_asked = f.trip == 0 && (f.state == static_cast<std::uint8_t>(State::kStopping) ||
                                         f.state == static_cast<std::uint8_t>(State::kDisabled));
  if (a_.first_full_gain_s >= 0.0 && have_prev_ && !off_asked) {
    const std::uint64_t ticks = f.tick > prev_tick_ ? f.tick - prev_tick_ : 1;  // and the ones missed before it
    a_.asked_s += static_cast<double>(ticks) * period_s_;
    // This tick on a stale or invalid sample: the command was not the controller's (the missed ticks
    // before it held the last command, which was).
    const bool held = !(f.flags & kFlagFresh) || f.invalid_samples > prev_invalid_;
    if (full) {
      a_.active_s += static_cast<double>(held ? ticks - 1 : ticks) * period_s_;
      a_.missed_while_active_s += static_cast<double>(ticks - 1) * period_s_;
      if (held) a_.sensor_held_s += period_s_;
      if (f.flags & kFlagDerated) a_.derated_s += period_s_;
    }
  }
  have_prev_ = true;
  prev_tick_ = f.tick;
  prev_invalid_ = f.invalid_samples;
  // Trips: a new one when the latched trip appears; safe when the command is zero with the amplifier off;
  // over when the loop is at full gain again.
  if (f.trip != 0 && !in_trip_) {
    in_trip_ = true;
    ++a_.trips_total;
    open_ = nullptr;
    if (a_.trips.size() < Availability::kMaxTrips) {
      a_.trips.push_back({to_string(static_cast<Trip>(f.trip)), f.time_s});
      open_ = &a_.trips.back();
    }
  }
  if (in_trip_ && open_ && open_->safe_s < 0.0 && f.command_v == 0.0 && !(f.flags & kFlagAmplifierEnable))
    open_->safe_s = f.time_s;
  if (in_trip_ && open_ && open_->rearmed_s < 0.0 && active && f.trip == 0) open_->rearmed_s = f.time_s;
  if (in_trip_ && f.trip == 0 && full) {
    if (open_) open_->full_gain_again_s = f.time_s;
    in_trip_ = false;
    open_ = nullptr;
  }
}

}  // namespace robodamp::rt
