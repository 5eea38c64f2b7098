// `robodamp filters`: magnitude and phase of each block and of the chain, analog and as realised.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/chain_design.hpp"

namespace robodamp::apps {

[[nodiscard]] nlohmann::json filters_report(const analysis::ChainDesign& d, double freq_hz);
[[nodiscard]] std::string filters_table(const nlohmann::json& report);
// Bode diagram of the blocks and the chain (like the paper's Figure 7). Empty string on success.
[[nodiscard]] std::string plot_filters(const analysis::ChainDesign& d, const std::string& png_path);

}  // namespace robodamp::apps
