// The command that commissions the cell again as it was called, for the written configuration's header and
// the report: the options a person gave, spelled as `robodamp commission` reads them (defaults left out where
// the settings hold them).
#pragma once

#include <string>

#include "commission/commission.hpp"
#include "commission/path_commission.hpp"

namespace robodamp::commission {

[[nodiscard]] std::string command_line(const CommissionSettings& s);
[[nodiscard]] std::string command_line(const PathCommissionSettings& s);

}  // namespace robodamp::commission
