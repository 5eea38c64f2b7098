// What `robodamp filters` reports of a configuration's chain (docs/commands.md): each block's and the chain's
// magnitude and phase at a frequency, analog and digital, as JSON and a table, and the Bode diagram. Off the
// real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "analysis/chain_design.hpp"

namespace robodamp::analysis {

[[nodiscard]] nlohmann::json filters_report(const ChainDesign& d, double freq_hz);
[[nodiscard]] std::string filters_table(const nlohmann::json& report);
// The blocks' and the chain's Bode diagram (PNG), the match frequency marked; an empty string, or what went wrong.
[[nodiscard]] std::string plot_filters(const ChainDesign& d, const std::string& png_path);

}  // namespace robodamp::analysis
