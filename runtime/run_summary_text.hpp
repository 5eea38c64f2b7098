// `robodamp run`'s summary, as text (an operator's reading order) and as JSON (the documented shape,
// docs/cli.md): the loop's timing, the supervisor's counters and events, availability, the devices, the
// speed schedule, the machining state and the last advice.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "runtime/run_summary.hpp"

namespace robodamp::runtime {

[[nodiscard]] nlohmann::json summary_json(const runtime::RunSummary& s);
[[nodiscard]] std::string summary_text(const runtime::RunSummary& s);
// The loop's wake-up latency histogram in the layout of cyclictest's --histfile (whole-microsecond bins, then
// the totals as "# Name: value" lines), so one script reads both. False when the file cannot be written.
[[nodiscard]] bool write_latency_histogram(const std::string& path, const runtime::RunSummary& s);

}  // namespace robodamp::runtime
