// The Modbus registers' scaling, encoded by the HIL emulator (hil/emulator_registers.hpp) and decoded by
// the supervisory client (drivers/modbus_client): one codec, as the CAN frames have one
// (drivers/can_codec). The counts per unit come from the modbus section (config/supervisory_config.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace robodamp::drivers::modbus_codec {

inline constexpr std::uint16_t kDepthUnavailable = 65535;     // depth register: the robot does not say
inline constexpr std::int16_t kJointUnavailable = INT16_MIN;  // joint register: the angle is not known

// Spindle speed: unsigned counts of rpm_per_count.
[[nodiscard]] inline std::uint16_t encode_rpm(double rpm, double rpm_per_count) {
  return static_cast<std::uint16_t>(std::clamp(std::lround(rpm / rpm_per_count), 0L, 65535L));
}
[[nodiscard]] inline double decode_rpm(std::uint16_t v, double rpm_per_count) { return v * rpm_per_count; }

// Axial depth of the robot program's cut: unsigned counts of depth_mm_per_count; NaN = not available.
[[nodiscard]] inline std::uint16_t encode_depth_mm(double mm, double depth_mm_per_count) {
  return static_cast<std::uint16_t>(std::isfinite(mm) ? std::clamp(std::round(mm / depth_mm_per_count), 0.0, 65534.0)
                                                      : static_cast<double>(kDepthUnavailable));
}
[[nodiscard]] inline double decode_depth_mm(std::uint16_t v, double depth_mm_per_count) {
  return v == kDepthUnavailable ? std::numeric_limits<double>::quiet_NaN() : v * depth_mm_per_count;
}

// A joint angle: signed counts of deg_per_count; NaN = not available.
[[nodiscard]] inline std::uint16_t encode_joint_deg(double deg, double deg_per_count) {
  const double counts = std::isfinite(deg) ? std::clamp(std::round(deg / deg_per_count), -32767.0, 32767.0)
                                           : static_cast<double>(kJointUnavailable);
  return static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
}
[[nodiscard]] inline double decode_joint_deg(std::uint16_t v, double deg_per_count) {
  const auto count = static_cast<std::int16_t>(v);
  return count == kJointUnavailable ? std::nan("") : count * deg_per_count;
}

// The amplifier's temperature: signed counts of temperature_c_per_count.
[[nodiscard]] inline std::uint16_t encode_temperature_c(double c, double temperature_c_per_count) {
  const double counts = std::clamp(std::round(c / temperature_c_per_count), -32768.0, 32767.0);
  return static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
}
[[nodiscard]] inline double decode_temperature_c(std::uint16_t v, double temperature_c_per_count) {
  return static_cast<std::int16_t>(v) * temperature_c_per_count;
}

// The spindle-speed advice block robodamp writes (modbus.robot.advice_register, 4 registers): sequence
// number, speed in rpm counts, margin x 100 (65535: not finite), status 1 = a stable speed found,
// 2 = none, 3 = withdrawn (the state it was for is gone before the spindle followed it: do not follow).
struct Advice {
  unsigned seq{0};
  unsigned status{0};
  double rpm{0.0};
  double margin{0.0};
};
[[nodiscard]] inline std::array<std::uint16_t, 4> encode_advice(std::uint64_t seq, bool found, double rpm,
                                                                double margin, double rpm_per_count) {
  auto count = [](double v) { return static_cast<std::uint16_t>(std::clamp(std::lround(v), 0L, 65535L)); };
  return {static_cast<std::uint16_t>(seq & 0xFFFFU), found ? count(rpm / rpm_per_count) : std::uint16_t{0},
          found && std::isfinite(margin) ? count(100.0 * margin) : static_cast<std::uint16_t>(found ? 65535 : 0),
          static_cast<std::uint16_t>(found ? 1 : 2)};
}
[[nodiscard]] inline std::array<std::uint16_t, 4> encode_withdrawn(std::uint64_t seq) {
  return {static_cast<std::uint16_t>(seq & 0xFFFFU), 0, 0, 3};
}
[[nodiscard]] inline Advice decode_advice(const std::array<std::uint16_t, 4>& a, double rpm_per_count) {
  return {a[0], a[3], a[1] * rpm_per_count, a[2] / 100.0};
}

}  // namespace robodamp::drivers::modbus_codec
