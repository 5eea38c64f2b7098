#include "identify/numeric_csv.hpp"

#include "measfiles/table.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace robodamp::identify {

NumericCsv read_numeric_csv(const std::string& path, const std::string& header_prefix, const std::string& header_shown,
                            std::size_t columns) {
  const measfiles::Table t = measfiles::read_table(path);
  std::vector<measfiles::ColumnSpec> wanted;
  std::istringstream names(header_prefix);
  for (std::string n; wanted.size() < columns && std::getline(names, n, ',');) wanted.push_back({{n}, std::nullopt});
  if (!t.names.empty()) {
    for (std::size_t k = 0; k < wanted.size(); ++k)
      if (k >= t.names.size() || measfiles::normalised(t.names[k]) != wanted[k].names.front())
        throw std::invalid_argument(path + ":" + std::to_string(t.header_line) + ": the header must be " +
                                    header_shown + " (or no header, the columns in that order)");
  } else if (t.columns < columns) {
    throw std::invalid_argument(path + ":" + std::to_string(t.lines.front()) + ": " + std::to_string(columns) +
                                " values expected");
  }
  NumericCsv csv;
  for (std::size_t k = 0; k < t.names.size(); ++k) csv.header += (k > 0 ? "," : "") + t.names[k];
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    csv.rows.emplace_back(t.rows[i].begin(), t.rows[i].begin() + static_cast<long>(columns));
    csv.lines.push_back(t.lines[i]);
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
  if (t.size() < 64)
    throw std::invalid_argument(path + ": too few samples (" + std::to_string(t.size()) + ", at least 64)");
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(std::abs(t[i] - t[i - 1] - dt) <= 1e-6 * dt))
      throw std::invalid_argument(path + ":" + std::to_string(csv.lines[i]) +
                                  ": the time step changes (a constant sample rate is needed)");
  ts.fs_hz = 1.0 / dt;
  return ts;
}

}  // namespace robodamp::identify
