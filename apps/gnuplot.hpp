// Headless PNG plots through gnuplot (gnuplot-nox, pngcairo), off the real-time path.
#pragma once

#include <functional>
#include <string>

#include "plot/gnuplot.hpp"

namespace robodamp::apps {

using plot::run_gnuplot;

// A report on stdout (JSON or the table), then the plot if a target is given: plot() returns the reason it
// failed or an empty string, and "wrote <what>" goes to stdout (stderr with JSON, to keep stdout parseable).
// Returns 0, or 1 when the plot failed.
[[nodiscard]] int print_report(const std::string& json_text, bool json, const std::string& table,
                               const std::string& plot_target, const std::function<std::string()>& plot,
                               const std::string& wrote);

}  // namespace robodamp::apps
