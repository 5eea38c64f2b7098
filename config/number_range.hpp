// The allowed interval of a number with its unit, and the one wording every refusal uses, whether the
// number comes from a configuration key, a command-line option or a parameter request:
//   "key = value unit is out of range: allowed min <= value <= max unit (why)".
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace robodamp::config {

// An open end excludes the bound itself.
struct Range {
  std::string_view unit;  // a literal: "Hz", "s", "(loop ticks)"
  double min;
  double max;
  bool min_open{false};
  bool max_open{false};
  std::string note{};  // why the bound, e.g. "Nyquist of loop.rate_hz = 5000 Hz"
};

[[nodiscard]] std::string format_number(double v);
// "allowed 0 < value <= 10 s (note)"
[[nodiscard]] std::string describe_range(const Range& r);
[[nodiscard]] bool in_range(double v, const Range& r);
// "key = value unit is out of range: allowed ...", or nothing when v is finite and in range.
[[nodiscard]] std::optional<std::string> range_problem(const std::string& key, double v, const Range& range);

}  // namespace robodamp::config
