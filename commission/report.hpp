// The commissioning report (DIR/report.html): one self-contained page (the plots inlined as PNG data URIs)
// with what each stage measured, fitted, tuned and verified, every number with its unit, the method that made
// each depth, and the command. The plots are also kept as DIR/plots/*.png, with their data.
#pragma once

#include <string>

#include "commission/commission.hpp"

namespace robodamp::commission {

// Returns an empty string, or why the report could not be written.
[[nodiscard]] std::string write_report(const CommissionSettings& s, const CommissionResult& r, const std::string& path);

}  // namespace robodamp::commission
