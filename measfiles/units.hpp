// Unit labels as instruments write them ("mm", "m/s^2", "g", "kN", "lbf", "ms", "Hz"), as a quantity and
// the factor to its SI unit. Off the real-time path.
#pragma once

#include <optional>
#include <string>

namespace robodamp::measfiles {

enum class Quantity { kLength, kVelocity, kAcceleration, kForce, kVoltage, kTime, kFrequency, kRatio };

struct UnitScale {
  Quantity quantity{Quantity::kRatio};
  double to_si{1.0};  // value in the unit x to_si = value in m, m/s, m/s^2, N, V, s, Hz
};

// nullopt for a label it does not know (empty and "NONE" too).
[[nodiscard]] std::optional<UnitScale> unit_scale(const std::string& label);
[[nodiscard]] const char* si_unit(Quantity q);

}  // namespace robodamp::measfiles
