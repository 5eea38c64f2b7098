// The universal file's fields (measfiles/uff.hpp): fixed Fortran columns first, free spacing second, and
// numbers run together split where a sign starts a new one. Shared by the reader's datasets; internal.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace robodamp::measfiles::detail {

// Where a problem is: the file, the dataset's number in it and its first line.
struct Context {
  std::string file;
  int index{0};    // 1 for the file's first dataset
  int dataset{0};  // its type (58, 15, ...)
  int line{0};     // the line being read
  // "FILE:LINE: dataset I (type T), record R: " (record 0: no record).
  [[nodiscard]] std::string where(int record) const;
};

[[nodiscard]] std::string trimmed(const std::string& s);
[[nodiscard]] std::string shown(double v);

// Appends every number of a line: fields spaced freely or run together ("1.0E+00-2.0E+00"), Fortran D
// exponents. Throws UffError naming the line and the text that is not a number.
void numbers_in(const std::string& line, std::vector<double>& out, const Context& c);

struct Record6 {
  std::array<int, 8> ints{};  // type, id, version, load case, response node, dir, reference node, dir
  std::string response_entity, reference_entity;
};
[[nodiscard]] Record6 record6_fields(const std::string& line, const Context& c);

struct Record7 {
  int ordinate_type{0}, points{0}, spacing{0};
  double min{0.0}, step{0.0}, z_value{0.0};
};
[[nodiscard]] Record7 record7_fields(const std::string& line, const Context& c);

struct AxisFields {
  std::array<int, 4> ints{};
  std::string label, units;
};
[[nodiscard]] AxisFields axis_fields(const std::string& line, const Context& c, int record);

}  // namespace robodamp::measfiles::detail
