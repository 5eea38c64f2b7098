#include "sim_plant/fault_text.hpp"

#include <sstream>
#include <vector>

#include "config/number_text.hpp"

namespace robodamp::sim {

bool parse_fault(const std::string& text, double run_s, Fault& out, std::string& error) {
  const auto fail = [&](const std::string& why) {
    error = "'" + text + "' " + why;
    return false;
  };
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
  if (parts.size() < 2 || parts.size() > 4)
    return fail("is not KIND:START_S[:DURATION_S] (actuator_saturated:START_S:DURATION_S[:FORCE_N])");
  Fault f;
  bool known = false;
  std::string kinds;
  for (int k = 0; k <= static_cast<int>(FaultKind::kDriverStall); ++k) {
    const auto kind = static_cast<FaultKind>(k);
    kinds += std::string(kinds.empty() ? "" : ", ") + to_string(kind);
    if (parts[0] == to_string(kind)) f.kind = kind, known = true;
  }
  if (!known) return fail("names no fault: allowed " + kinds);
  if (auto p = config::parse_number("--fault start", parts[1], {"s", 0.0, run_s, false, false, "within --duration"},
                                    false, f.start_s))
    return fail(*p);
  if (parts.size() >= 3)
    if (auto p = config::parse_number("--fault duration", parts[2], {"s", 0.0, 604800.0, true}, false, f.duration_s))
      return fail(*p);
  if (f.kind == FaultKind::kActuatorSaturated) f.magnitude = 0.0;
  if (parts.size() == 4) {
    if (f.kind != FaultKind::kActuatorSaturated)
      return fail("has a fourth field: only actuator_saturated takes one (FORCE_N)");
    if (auto p = config::parse_number("--fault force", parts[3], {"N", 0.0, 1e6}, false, f.magnitude)) return fail(*p);
  }
  out = f;
  return true;
}

}  // namespace robodamp::sim
