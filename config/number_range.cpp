#include "config/number_range.hpp"

#include <cmath>
#include <sstream>

namespace robodamp::config {

std::string format_number(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

std::string describe_range(const Range& r) {
  std::ostringstream os;
  os << "allowed " << format_number(r.min) << (r.min_open ? " < " : " <= ") << "value" << (r.max_open ? " < " : " <= ")
     << format_number(r.max) << ' ' << r.unit;
  if (!r.note.empty()) os << " (" << r.note << ')';
  return os.str();
}

bool in_range(double v, const Range& r) {
  const bool lo = r.min_open ? v > r.min : v >= r.min;
  const bool hi = r.max_open ? v < r.max : v <= r.max;
  return lo && hi;
}

std::optional<std::string> range_problem(const std::string& key, double v, const Range& range) {
  if (std::isfinite(v) && in_range(v, range)) return std::nullopt;
  return key + " = " + format_number(v) + ' ' + std::string(range.unit) + " is out of range: " + describe_range(range);
}

}  // namespace robodamp::config
