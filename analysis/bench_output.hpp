// What `robodamp bench` prints and writes of a bench run (docs/simulation.md, "Main job"): its table in the
// style of the paper's Tables 3 and 4, its JSON, and its plots (the gain sweep's envelopes, the measured and
// predicted improvements). Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "analysis/bench_run.hpp"

namespace robodamp::analysis {

[[nodiscard]] nlohmann::json bench_report_json(const Bench& bench, const BenchReport& r);
[[nodiscard]] std::string bench_table(const Bench& bench, const BenchReport& r);
// bench_sweep.png and bench_improvement.png in dir; an empty string, or what went wrong.
[[nodiscard]] std::string plot_bench(const Bench& bench, const BenchReport& r, const std::string& dir);

}  // namespace robodamp::analysis
