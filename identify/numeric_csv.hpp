// Reading the identification tools' CSV inputs: a required header, then rows of numbers. Off the
// real-time path.
#pragma once

#include <string>
#include <vector>

namespace robodamp::identify {

struct NumericCsv {
  std::string header;                     // the file's first line
  std::vector<std::vector<double>> rows;  // each exactly `columns` numbers (NaN and inf are passed on)
  std::vector<int> lines;                 // each row's line number in the file
};

// Lines starting with # are comments. The header must start with header_prefix; every non-empty row must hold `columns` numbers. Throws
// std::invalid_argument naming the file and line of the first problem.
[[nodiscard]] NumericCsv read_numeric_csv(const std::string& path, const std::string& header_prefix,
                                          const std::string& header_shown, std::size_t columns);

// Two channels against time at a constant rate: `time_s,<input>,<output>` (the header given), at least
// 64 finite rows. Throws std::invalid_argument naming the file and line of the first problem.
struct TimeSeries {
  double fs_hz{0.0};
  std::vector<double> input, output;
};
[[nodiscard]] TimeSeries read_time_series_csv(const std::string& path, const std::string& header);

}  // namespace robodamp::identify
