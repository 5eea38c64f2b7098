// `robodamp analyze`: stability, margins, the gain limit, the polarity and the predicted improvement of
// the damping loop (continuous model and the discrete loop that runs), as a table, JSON and plots.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/loop_model.hpp"

namespace robodamp::apps {

[[nodiscard]] nlohmann::json analysis_report(const analysis::LoopModel& m, const analysis::AnalysisResult& r);
[[nodiscard]] std::string analysis_table(const nlohmann::json& report);
// frf_open_closed.png, nyquist.png, gain_sweep.png in dir. Empty string on success, else the reason.
[[nodiscard]] std::string plot_analysis(const analysis::LoopModel& m, const analysis::AnalysisResult& r,
                                        const std::string& dir);

}  // namespace robodamp::apps
