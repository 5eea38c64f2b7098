// How `robodamp run` (its summary) and `robodamp monitor` show a spindle-speed advice
// (runtime/speed_advisor.hpp; the DDS advice topic's fields).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dds/bridge.hpp"

namespace robodamp::runtime {

// One line (or two when none qualifies), ending in a newline.
[[nodiscard]] std::string advice_text(const dds::AdviceSample& a);
[[nodiscard]] nlohmann::json advice_json(const dds::AdviceSample& a);

}  // namespace robodamp::runtime
