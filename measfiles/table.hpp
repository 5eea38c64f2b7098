// Delimited tables the way people and loggers save them (docs/measurement_files.md): comma, semicolon,
// tab or spaces between fields; a decimal comma (with ; tab or spaces between fields); a UTF-8 byte-order
// mark; CRLF line ends; comment lines (#); a header or none, a units row or units in the header
// ("Fx [N]", "Fx (kN)", "Fx/N"); preamble lines a logger writes before it. One reader for all of
// robodamp's tabular inputs. Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "measfiles/units.hpp"

namespace robodamp::measfiles {

struct Table {
  std::vector<std::string> names;         // per column as written, units removed (empty: the file has no header)
  std::vector<std::string> units;         // per column as written ("" when none)
  std::vector<std::vector<double>> rows;  // every row has names.size() or columns values
  std::vector<int> lines;                 // each row's line in the file
  std::size_t columns{0};
  char delimiter{','};  // ' ' for spaces
  bool decimal_comma{false};
  int header_line{0};  // 0: none
};

// Throws std::invalid_argument naming the file and line: no data, a row whose field count differs from
// the first row's, a field that is not a number (NaN and inf are passed on: the caller decides).
[[nodiscard]] Table read_table(const std::string& path);
[[nodiscard]] Table parse_table(const std::string& text, const std::string& name);

// One column a reader wants: its names (lower case, any of them), the quantity and unit its values are
// returned in (SI), or a unit of its own the name carries ("freq_hz" needs none).
struct ColumnSpec {
  std::vector<std::string> names;
  std::optional<Quantity> quantity;  // converted to SI when the header gives a unit of this quantity
};

// A column name compared: lower case, spaces and dashes as underscores.
[[nodiscard]] std::string normalised(const std::string& name);

// The columns wanted, in their order: by name when the file has a header (units converted, a unit of the
// wrong quantity refused), by position when it has none. Throws std::invalid_argument naming the column.
[[nodiscard]] std::vector<std::vector<double>> select_columns(const Table& t, const std::vector<ColumnSpec>& wanted,
                                                              const std::string& name, const std::string& shown);

}  // namespace robodamp::measfiles
