#include "hil/program_text.hpp"

#include <tuple>
#include <vector>

#include "config/number_text.hpp"

namespace robodamp::hil {

namespace {
const config::Range kPlantTime{"s", 0.0, 1e7};
}  // namespace

bool parse_mounting(const std::string& item, std::pair<double, config::Mounting>& out, std::string& error) {
  const auto colon = item.find(':');
  double t = 0.0;
  const std::string m = colon == std::string::npos ? "" : item.substr(colon + 1);
  if (colon == std::string::npos || config::parse_number("--mounting", item.substr(0, colon), kPlantTime, false, t) ||
      (m != "horizontal" && m != "vertical")) {
    error =
        "--mounting = '" + item + "': expected TIME_S:horizontal or TIME_S:vertical, allowed 0 <= TIME_S <= 1e+07 s";
    return false;
  }
  out = {t, m == "vertical" ? config::Mounting::kVertical : config::Mounting::kHorizontal};
  return true;
}

bool parse_change(const std::string& option, const std::string& item, const config::Range& value, bool ramp,
                  SpindleChange& out, std::string& error) {
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const auto colon = item.find(':', from);
    parts.push_back(item.substr(from, colon == std::string::npos ? std::string::npos : colon - from));
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  SpindleChange c;
  const bool ok = parts.size() == (ramp ? 3U : 2U) &&
                  !config::parse_number(option, parts[0], kPlantTime, false, c.t0_s) &&
                  (!ramp || !config::parse_number(option, parts[1], kPlantTime, false, c.t1_s)) &&
                  !config::parse_number(option, parts.back(), value, false, c.rpm) && (!ramp || c.t1_s >= c.t0_s);
  if (!ramp) c.t1_s = c.t0_s;
  if (ok) {
    out = c;
    return true;
  }
  const std::string v = value.unit == "rpm" ? "RPM" : "MM";
  error = option + " = '" + item + "': expected " + (ramp ? "T0_S:T1_S:" : "TIME_S:") + v +
          ", allowed 0 <= " + (ramp ? "T0_S <= T1_S" : "TIME_S") + " <= 1e+07 s and " +
          config::format_number(value.min) + " <= " + v + " <= " + config::format_number(value.max) + ' ' +
          std::string(value.unit);
  return false;
}

bool apply_program(const ProgramText& text, EmulatorOptions& eo, std::string& error) {
  for (const auto& item : text.mounting)
    if (!parse_mounting(item, eo.mounting_schedule.emplace_back(), error)) return false;
  const config::Range rpm_range{"rpm", 0.0, 200000.0}, mm_range{"mm", 0.0, 100.0};
  for (const auto& item : text.spindle) {
    SpindleChange c;
    if (!parse_change("--spindle", item, rpm_range, false, c, error)) return false;
    eo.spindle_schedule.emplace_back(c.t0_s, c.rpm);
  }
  for (const auto& [items, option, range, ramp, out] :
       {std::tuple{&text.depth, "--depth", &mm_range, false, &eo.depth_changes},
        std::tuple{&text.spindle_ramps, "--spindle-ramp", &rpm_range, true, &eo.spindle_ramps},
        std::tuple{&text.depth_ramps, "--depth-ramp", &mm_range, true, &eo.depth_changes}})
    for (const auto& item : *items)
      if (!parse_change(option, item, *range, ramp, out->emplace_back(), error)) return false;
  for (const auto& item : text.pose_at)
    if (!parse_waypoint(item, eo.pose_trajectory.emplace_back(), error)) {
      error.insert(0, "--pose-at = ");
      return false;
    }
  return true;
}

}  // namespace robodamp::hil
