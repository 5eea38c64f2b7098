#include "identify/numeric_csv.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace robodamp::identify {

NumericCsv read_numeric_csv(const std::string& path, const std::string& header_prefix, const std::string& header_shown,
                            std::size_t columns) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  NumericCsv csv;
  int number = 1;
  while (std::getline(in, csv.header) && !csv.header.empty() && csv.header[0] == '#') ++number;  // comments first
  if (csv.header.substr(0, header_prefix.size()) != header_prefix)
    throw std::invalid_argument(path + ":" + std::to_string(number) + ": the header must be " + header_shown);
  std::string line;
  for (++number; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream row(line);
    std::string cell;
    std::vector<double> values;
    while (values.size() < columns && std::getline(row, cell, ',')) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (cell.empty() || end == cell.c_str() || *end != '\0')
        throw std::invalid_argument(path + ":" + std::to_string(number) + ": '" + cell + "' is not a number");
      values.push_back(v);
    }
    if (values.size() != columns)
      throw std::invalid_argument(path + ":" + std::to_string(number) + ": " + std::to_string(columns) + " values expected");
    csv.rows.push_back(std::move(values));
    csv.lines.push_back(number);
  }
  return csv;
}

TimeSeries read_time_series_csv(const std::string& path, const std::string& header) {
  const NumericCsv csv = read_numeric_csv(path, header, header, 3);
  std::vector<double> t;
  TimeSeries ts;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& v = csv.rows[i];
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw std::invalid_argument(path + ":" + std::to_string(csv.lines[i]) + ": a value is not a finite number");
    t.push_back(v[0]), ts.input.push_back(v[1]), ts.output.push_back(v[2]);
  }
  if (t.size() < 64) throw std::invalid_argument(path + ": too few samples (" + std::to_string(t.size()) + ", at least 64)");
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(std::abs(t[i] - t[i - 1] - dt) <= 1e-6 * dt))
      throw std::invalid_argument(path + ":" + std::to_string(csv.lines[i]) + ": the time step changes (a constant sample rate is needed)");
  ts.fs_hz = 1.0 / dt;
  return ts;
}

}  // namespace robodamp::identify
