// Availability: how much of the time a cell was asked to damp it damped at full gain (docs/runtime.md,
// "Soak"). Fed every telemetry frame on the drain thread; off the real-time path.
//  - asked: from the first tick the loop reached full gain (armed, and gain_ramp_s after it became active)
//    to the end of the run; the start-up's arming and fade are not an outage. Ticks stopping or disabled
//    with no trip (the run's end, an operator's disarm) are not asked.
//  - active: the time of it in the active state past the fade-in, derated or not (derated_s apart) (the "armed and at full gain"), with
//    the ticks the loop missed meanwhile (a stall: the amplifier held the last command) also counted apart;
//    ticks on a stale or invalid sample (the command zero, ridden through) are not active, counted apart.
//  - each trip: its class, when it tripped, when the command was zero with the amplifier off (safe), and
//    when the loop was at full gain again (re-armed by the recovery policy or an operator), if it was.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "rt/telemetry_frame.hpp"

namespace robodamp::rt {

struct TripRecord {
  std::string trip;  // rt::Trip's name
  double trip_s{0.0};
  double safe_s{-1.0};             // -1: not safe before the run ended
  double rearmed_s{-1.0};          // active again (the fade-in starts); -1: never again
  double full_gain_again_s{-1.0};  // -1: never again (latched, or the run ended first)
};

struct Availability {
  double asked_s{0.0}, active_s{0.0};
  double missed_while_active_s{0.0};  // of active_s: ticks the loop missed (the command held, not updated)
  // At full gain on a stale or invalid sample, the controller's part of the command zero: not damping,
  // so not in active_s (a stale sensor ridden through without a trip).
  double sensor_held_s{0.0};
  // Of active_s: the command derated (supervision.derate: armed and damping, at a lowered gain).
  double derated_s{0.0};
  double first_full_gain_s{-1.0};  // -1: never at full gain
  std::uint64_t trips_total{0};
  std::vector<TripRecord> trips;  // the first kMaxTrips
  static constexpr std::size_t kMaxTrips = 256;
  [[nodiscard]] double share() const { return asked_s > 0.0 ? active_s / asked_s : 0.0; }
};

class AvailabilityMeter {
 public:
  AvailabilityMeter(double rate_hz, double gain_ramp_s) : period_s_(1.0 / rate_hz), ramp_s_(gain_ramp_s) {
    a_.trips.reserve(Availability::kMaxTrips);  // open_ points into it
  }
  void on_frame(const TelemetryFrame& f);
  [[nodiscard]] const Availability& result() const { return a_; }

 private:
  double period_s_, ramp_s_;
  Availability a_;
  bool have_prev_{false}, in_trip_{false};
  std::uint64_t prev_tick_{0};
  std::uint32_t prev_invalid_{0};
  double active_since_s_{-1.0};
  TripRecord* open_{nullptr};  // the trip waiting for its safe time or its full gain again
};

}  // namespace robodamp::rt
