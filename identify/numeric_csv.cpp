#include "identify/numeric_csv.hpp"

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
  if (!std::getline(in, csv.header) || csv.header.substr(0, header_prefix.size()) != header_prefix)
    throw std::invalid_argument(path + ":1: the header must be " + header_shown);
  std::string line;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
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

}  // namespace robodamp::identify
