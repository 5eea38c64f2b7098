// `robodamp bench`: the simulated-plant bench run (averaged impact tests, control off and on, saturating
// impacts, gain sweep) as a table in the style of the paper's Tables 3 and 4, JSON and plots.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/bench_run.hpp"

namespace robodamp::apps {

[[nodiscard]] nlohmann::json bench_report_json(const analysis::Bench& bench, const analysis::BenchReport& r);
[[nodiscard]] std::string bench_table(const analysis::Bench& bench, const analysis::BenchReport& r);
// bench_sweep.png (command envelopes of the gain sweep) and bench_improvement.png in dir.
[[nodiscard]] std::string plot_bench(const analysis::Bench& bench, const analysis::BenchReport& r,
                                     const std::string& dir);

}  // namespace robodamp::apps
