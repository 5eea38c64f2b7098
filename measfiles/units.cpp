#include "measfiles/units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <utility>

namespace robodamp::measfiles {

namespace {

struct Known {
  const char* label;
  Quantity quantity;
  double to_si;
};

constexpr double kG = 9.80665;            // standard gravity, m/s^2
constexpr double kInch = 0.0254;          // m
constexpr double kLbf = 4.4482216152605;  // N

constexpr std::array kKnown{
    Known{"m", Quantity::kLength, 1.0},
    Known{"mm", Quantity::kLength, 1e-3},
    Known{"um", Quantity::kLength, 1e-6},
    Known{"micron", Quantity::kLength, 1e-6},
    Known{"in", Quantity::kLength, kInch},
    Known{"m/s", Quantity::kVelocity, 1.0},
    Known{"mm/s", Quantity::kVelocity, 1e-3},
    Known{"in/s", Quantity::kVelocity, kInch},
    Known{"m/s^2", Quantity::kAcceleration, 1.0},
    Known{"mm/s^2", Quantity::kAcceleration, 1e-3},
    Known{"g", Quantity::kAcceleration, kG},
    Known{"in/s^2", Quantity::kAcceleration, kInch},
    Known{"n", Quantity::kForce, 1.0},
    Known{"kn", Quantity::kForce, 1e3},
    Known{"lbf", Quantity::kForce, kLbf},
    Known{"lb", Quantity::kForce, kLbf},
    Known{"v", Quantity::kVoltage, 1.0},
    Known{"mv", Quantity::kVoltage, 1e-3},
    Known{"s", Quantity::kTime, 1.0},
    Known{"sec", Quantity::kTime, 1.0},
    Known{"ms", Quantity::kTime, 1e-3},
    Known{"hz", Quantity::kFrequency, 1.0},
    Known{"rad/s", Quantity::kFrequency, 1.0 / (2.0 * M_PI)},
    Known{"khz", Quantity::kFrequency, 1e3},
};

// Lower case, no spaces, the spellings of a square and of micro folded: "m/s**2", "m/s2", "m s^-2",
// "µm" and "μm" all read as the one label.
std::string folded(const std::string& label) {
  std::string s;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const auto c = static_cast<unsigned char>(label[i]);
    if (c == 0xC2 && i + 1 < label.size() && static_cast<unsigned char>(label[i + 1]) == 0xB5) {  // U+00B5 micro sign
      s += 'u', ++i;
    } else if (c == 0xCE && i + 1 < label.size() && static_cast<unsigned char>(label[i + 1]) == 0xBC) {  // U+03BC mu
      s += 'u', ++i;
    } else if (c == 0xC2 && i + 1 < label.size() &&
               static_cast<unsigned char>(label[i + 1]) == 0xB2) {  // superscript 2
      s += "^2", ++i;
    } else if (!std::isspace(c)) {
      s += static_cast<char>(std::tolower(c));
    }
  }
  for (const auto& [from, to] :
       {std::pair{"**2", "^2"}, std::pair{"s2", "s^2"}, std::pair{"s^-2", "/s^2"}, std::pair{"sec", "s"}}) {
    const std::size_t at = s.find(from);
    if (at != std::string::npos && !(std::string(from) == "s2" && s.find("s^2") != std::string::npos))
      s.replace(at, std::string(from).size(), to);
  }
  if (s.rfind("ms^-1", 0) == 0) s = "m/s";
  return s;
}

}  // namespace

std::optional<UnitScale> unit_scale(const std::string& label) {
  const std::string s = folded(label);
  if (s.empty() || s == "none") return std::nullopt;
  for (const auto& k : kKnown)
    if (s == k.label) return UnitScale{k.quantity, k.to_si};
  return std::nullopt;
}

const char* si_unit(Quantity q) {
  switch (q) {
    case Quantity::kLength:
      return "m";
    case Quantity::kVelocity:
      return "m/s";
    case Quantity::kAcceleration:
      return "m/s^2";
    case Quantity::kForce:
      return "N";
    case Quantity::kVoltage:
      return "V";
    case Quantity::kTime:
      return "s";
    case Quantity::kFrequency:
      return "Hz";
    case Quantity::kRatio:
      return "1";
  }
  return "";
}

}  // namespace robodamp::measfiles
