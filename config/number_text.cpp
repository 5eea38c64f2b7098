#include "config/number_text.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace robodamp::config {

std::optional<std::string> parse_number(const std::string& flag, const std::string& text, const Range& range,
                                        bool whole, double& out) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  const bool parsed = !text.empty() && end != begin && *end == '\0' && errno != ERANGE;
  if (!parsed || !std::isfinite(v)) return flag + " = '" + text + "' is not a finite number: " + describe_range(range);
  if (auto p = range_problem(flag, v, range)) return p;
  if (whole && v != std::floor(v))
    return flag + " = " + format_number(v) + " is not a whole number: " + describe_range(range);
  out = v;
  return std::nullopt;
}

}  // namespace robodamp::config
