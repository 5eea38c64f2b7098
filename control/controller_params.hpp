// Everything the real-time controller needs, in a fixed-size struct that can be prepared off the
// real-time thread and handed over by copy (no allocation).
#pragma once

#include <array>
#include <utility>

#include "filters/biquad.hpp"
#include "filters/harmonic_notch.hpp"

namespace robodamp::control {

struct ControllerParams {
  double fs_hz{5000.0};
  filters::SosCoefficients sections{};
  double sections_gain{1.0};  // H_filters(z) = sections_gain * prod sections
  double gain_ns_per_m{0.0};  // K
  double gain_ramp_s{0.5};    // time for any gain change (also a parameter-set hand-over fades out and in)
  double settle_s{0.0};       // time for the slowest pole's transient to fall to 1e-3 (from the design)
  int polarity{1};            // +1 / -1: force command = polarity * K * filters(accel)
  double actuator_constant_n_per_v{4.8};
  double force_limit_n{36.0};
  double voltage_limit_v{10.0};
  double slew_rate_v_per_s{10000.0};
  filters::HarmonicNotchSettings harmonic_notch{};  // spindle-locked notches after the chain (off by default)
  int spindle_teeth{3};
  double spindle_rpm_max{30000.0};
  // Speeds where the analysis refused the notches (analysis/notch_speed_map.hpp): a speed inside one
  // parks them. At most kMaxRefusedSpeeds intervals (the configuration time merges more).
  static constexpr std::size_t kMaxRefusedSpeeds = 8;
  std::array<std::pair<double, double>, kMaxRefusedSpeeds> refused_rpm{};
  std::size_t refused_rpm_count{0};
  // controller.speed_schedule: K by spindle speed. A speed in band i sets K to its gain (ramped over
  // gain_ramp_s); outside every band K is gain_ns_per_m. Ascending and disjoint; [rpm_min, rpm_max).
  // Each band names the parameter set (the supervisor's index) whose chain runs there; outside every band
  // set 0 runs at its gain_ns_per_m. Every set of a schedule carries the same table.
  struct SpeedBand {
    double rpm_min{0.0}, rpm_max{0.0}, gain_ns_per_m{0.0};
    std::size_t set{0};
  };
  static constexpr std::size_t kMaxSpeedBands = 64;
  std::array<SpeedBand, kMaxSpeedBands> speed_bands{};
  std::size_t speed_band_count{0};
  std::size_t set_index{0};  // which set these parameters are (the supervisor numbers them as it adds them)

  // RT-safe. The band holding rpm, or kMaxSpeedBands outside every band.
  [[nodiscard]] std::size_t speed_band_of(double rpm) const noexcept {
    for (std::size_t i = 0; i < speed_band_count; ++i) {
      const SpeedBand& b = speed_bands[i];
      if (rpm >= b.rpm_min && (rpm < b.rpm_max || (i + 1 == speed_band_count && rpm == b.rpm_max))) return i;
    }
    return kMaxSpeedBands;
  }
  [[nodiscard]] bool speed_scheduled() const noexcept { return speed_band_count > 0; }
  // Some band runs another set: the spindle speed chooses the set (a schedule of K alone does not).
  [[nodiscard]] bool speed_chooses_set() const noexcept {
    for (std::size_t i = 0; i < speed_band_count; ++i)
      if (speed_bands[i].set != set_index) return true;
    return false;
  }
  // RT-safe. The set the schedule runs at this speed: the band's; outside every band set 0 (the cell's own)
  // when the schedule chooses sets, this set when it schedules K alone.
  [[nodiscard]] std::size_t scheduled_set(double rpm) const noexcept {
    const std::size_t b = speed_band_of(rpm);
    if (b < speed_band_count) return speed_bands[b].set;
    return speed_chooses_set() ? 0 : set_index;
  }
  // RT-safe. The K these parameters run at this speed: the band's when the band names this set, K 0 when it
  // names another (the supervisor hands over to it), gain_ns_per_m outside every band on the set that runs there.
  [[nodiscard]] double scheduled_gain_ns_per_m(double rpm) const noexcept {
    if (!speed_scheduled()) return gain_ns_per_m;
    if (scheduled_set(rpm) != set_index) return 0.0;
    const std::size_t b = speed_band_of(rpm);
    return b < speed_band_count ? speed_bands[b].gain_ns_per_m : gain_ns_per_m;
  }
};

}  // namespace robodamp::control
