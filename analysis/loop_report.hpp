// What `robodamp analyze` and `robodamp bench` report of the damping loop (docs/commands.md): stability,
// margins, the gain limit, the polarity and the predicted improvement (continuous model and the discrete
// loop that runs) as JSON, a table and plots. Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "analysis/loop_model.hpp"

namespace robodamp::analysis {

[[nodiscard]] nlohmann::json analysis_report(const LoopModel& m, const AnalysisResult& r);
[[nodiscard]] std::string analysis_table(const nlohmann::json& report);
// frf_open_closed.png, nyquist.png, gain_sweep.png in dir (created). Empty string on success, else the reason.
[[nodiscard]] std::string plot_analysis(const LoopModel& m, const AnalysisResult& r, const std::string& dir);

}  // namespace robodamp::analysis
