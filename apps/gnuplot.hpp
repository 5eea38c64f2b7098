// Headless PNG plots through gnuplot (gnuplot-nox, pngcairo), off the real-time path.
#pragma once

#include <string>

namespace robodamp::apps {

// Writes `data` to a temporary file, runs `script` (which refers to it as DATA) and checks that
// gnuplot produced `png_path`. Returns an empty string on success, else the reason.
[[nodiscard]] std::string run_gnuplot(const std::string& script, const std::string& data, const std::string& png_path);

}  // namespace robodamp::apps
