// Headless PNG plots through gnuplot (gnuplot-nox, pngcairo), off the real-time path, and the PNG as a
// data URI for self-contained HTML reports.
#pragma once

#include <string>

namespace robodamp::plot {

// Writes `data` to a temporary file, runs `script` (which refers to it as DATA) and checks that
// gnuplot produced `png_path`. Returns an empty string on success, else the reason.
[[nodiscard]] std::string run_gnuplot(const std::string& script, const std::string& data, const std::string& png_path);

// The file as "data:image/png;base64,..." (OpenSSL's base64). Empty when it cannot be read.
[[nodiscard]] std::string png_data_uri(const std::string& png_path);

// A number for plot data: 10 significant digits, "NaN" when not finite (gnuplot skips it).
[[nodiscard]] std::string num(double v);

}  // namespace robodamp::plot
