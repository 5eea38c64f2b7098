// One number typed as text (a command-line option, a field of an option such as --fault's): finite, nothing
// after it, and in its range; refused in the wording every range refusal uses (config/number_range.hpp).
#pragma once

#include <optional>
#include <string>

#include "config/number_range.hpp"

namespace robodamp::config {

// Parses `text` into `out` and returns nothing, or leaves `out` as it was and returns the problem:
// "FLAG = 'TEXT' is not a finite number: allowed ...", the range's refusal, or, with `whole`, "is not a whole
// number".
[[nodiscard]] std::optional<std::string> parse_number(const std::string& flag, const std::string& text,
                                                      const Range& range, bool whole, double& out);

}  // namespace robodamp::config
