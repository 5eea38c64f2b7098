// The report of `robodamp commission --along-path` (commission/path_commission.hpp): DIR/report.html, self-
// contained (its plots inline), and DIR/report.json with the same numbers. Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace robodamp::commission {

struct PathCommissionSettings;
struct PathCommissionResult;

[[nodiscard]] nlohmann::json to_json(const PathCommissionResult& r);

// Writes html_path and report.json beside it; the plots' PNG and data under plots/ there. Returns an empty
// string, or why it could not write.
[[nodiscard]] std::string write_path_report(const PathCommissionSettings& s, const PathCommissionResult& r,
                                            const std::string& html_path);

}  // namespace robodamp::commission
