// The constants and unit conversions every library shares (one home each). Header-only: the INTERFACE
// library robodamp_units, below filters and config.
#pragma once

#include <numbers>

namespace robodamp {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;        // rad per revolution; Hz to rad/s
inline constexpr double kMmPerM = 1000.0;                       // millimetres per metre
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;  // degrees per radian (a ROS joint state's rad)
inline constexpr double kStandardGravityMps2 = 9.80665;         // m/s^2 per g (standard gravity)

}  // namespace robodamp
