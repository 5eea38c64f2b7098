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
};

}  // namespace robodamp::control
