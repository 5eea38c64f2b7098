#include "measfiles/uff_fields.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "measfiles/uff.hpp"

namespace robodamp::measfiles::detail {

namespace {

// A whole field as a number (D exponents read as E); false when it is not one.
bool to_double(std::string s, double& v) {
  for (char& ch : s)
    if (ch == 'D' || ch == 'd') ch = 'E';
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE;
}

bool to_int(const std::string& field, int& v) {
  const std::string s = trimmed(field);
  if (s.empty()) {  // Fortran reads a blank integer field as 0
    v = 0;
    return true;
  }
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(s.c_str(), &end, 10);
  if (end != s.c_str() + s.size() || errno == ERANGE || x < -2'000'000'000L || x > 2'000'000'000L) return false;
  v = static_cast<int>(x);
  return true;
}

std::vector<std::string> columns(const std::string& line, const std::vector<int>& widths) {
  std::vector<std::string> out;
  std::size_t at = 0;
  for (int w : widths) {
    out.push_back(at < line.size() ? line.substr(at, static_cast<std::size_t>(w)) : std::string());
    at += static_cast<std::size_t>(w);
  }
  return out;
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

}  // namespace

std::string Context::where(int record) const {
  std::string s = file + ":" + std::to_string(line) + ": dataset " + std::to_string(index);
  if (dataset != 0) s += " (type " + std::to_string(dataset) + ")";
  if (record > 0) s += ", record " + std::to_string(record);
  return s + ": ";
}

std::string trimmed(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

std::string shown(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

void numbers_in(const std::string& line, std::vector<double>& out, const Context& c) {
  for (const std::string& w : words(line)) {
    // A sign that does not follow an exponent letter starts the next number.
    std::size_t start = 0;
    for (std::size_t i = 1; i <= w.size(); ++i) {
      const bool cut =
          i == w.size() || ((w[i] == '-' || w[i] == '+') && std::string("EeDd").find(w[i - 1]) == std::string::npos);
      if (!cut) continue;
      double v = 0.0;
      const std::string part = w.substr(start, i - start);
      if (!to_double(part, v)) throw UffError(c.where(0) + "'" + part.substr(0, 30) + "' is not a number");
      out.push_back(v);
      start = i;
    }
  }
}

Record6 record6_fields(const std::string& line, const Context& c) {
  Record6 r;
  static const char* const kNames[] = {"function type", "function id",        "version",        "load case",
                                       "response node", "response direction", "reference node", "reference direction"};
  const std::vector<std::string> w = words(line);
  if (w.size() == 10) {
    const int at[8] = {0, 1, 2, 3, 5, 6, 8, 9};
    bool ok = true;
    for (int i = 0; i < 8 && ok; ++i)
      ok = to_int(w[static_cast<std::size_t>(at[i])], r.ints[static_cast<std::size_t>(i)]);
    if (ok) {
      r.response_entity = w[4], r.reference_entity = w[7];
      return r;
    }
  }
  const std::vector<std::string> f = columns(line, {5, 10, 5, 10, 11, 10, 4, 11, 10, 4});
  const int at[8] = {0, 1, 2, 3, 5, 6, 8, 9};
  for (int i = 0; i < 8; ++i)
    if (!to_int(f[static_cast<std::size_t>(at[i])], r.ints[static_cast<std::size_t>(i)]))
      throw UffError(c.where(6) + "field " + std::to_string(at[i] + 1) + " (" + kNames[i] + ") '" +
                     trimmed(f[static_cast<std::size_t>(at[i])]) + "' is not an integer");
  r.response_entity = trimmed(f[4]), r.reference_entity = trimmed(f[7]);
  return r;
}

Record7 record7_fields(const std::string& line, const Context& c) {
  static const char* const kNames[] = {"ordinate data type", "number of values",   "abscissa spacing",
                                       "abscissa minimum",   "abscissa increment", "z-axis value"};
  std::vector<double> v;
  try {
    numbers_in(line, v, c);
  } catch (const UffError&) {
    v.clear();
  }
  if (v.size() != 6) {  // run-together integers: the fixed columns
    v.clear();
    const std::vector<std::string> f = columns(line, {10, 10, 10, 13, 13, 13});
    for (std::size_t i = 0; i < f.size(); ++i) {
      double x = 0.0;
      if (!to_double(trimmed(f[i]), x))
        throw UffError(c.where(7) + "field " + std::to_string(i + 1) + " (" + kNames[i] + ") '" + trimmed(f[i]) +
                       "' is not a number");
      v.push_back(x);
    }
  }
  for (std::size_t i = 0; i < 3; ++i)
    if (v[i] != std::floor(v[i]) || std::abs(v[i]) > 2e9)
      throw UffError(c.where(7) + "field " + std::to_string(i + 1) + " (" + kNames[i] + ") = " + shown(v[i]) +
                     " is not an integer");
  return {static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]), v[3], v[4], v[5]};
}

AxisFields axis_fields(const std::string& line, const Context& c, int record) {
  AxisFields a;
  static const char* const kNames[] = {"specific data type", "length units exponent", "force units exponent",
                                       "temperature units exponent"};
  const std::vector<std::string> f = columns(line, {10, 5, 5, 5, 21, 21});
  bool fixed = true;
  for (std::size_t i = 0; i < 4 && fixed; ++i) fixed = to_int(f[i], a.ints[i]);
  if (fixed) {
    a.label = trimmed(f[4]), a.units = trimmed(f[5]);
    if (a.units.empty() && line.size() > 67) a.units = trimmed(line.substr(46));  // a label run past its 20 columns
    return a;
  }
  const std::vector<std::string> w = words(line);
  for (std::size_t i = 0; i < 4; ++i)
    if (i >= w.size() || !to_int(w[i], a.ints[i]))
      throw UffError(c.where(record) + "field " + std::to_string(i + 1) + " (" + kNames[i] + ") '" +
                     (i < w.size() ? w[i] : std::string()) + "' is not an integer");
  if (w.size() > 4) a.label = w[4];
  for (std::size_t i = 5; i < w.size(); ++i) a.units += (i > 5 ? " " : "") + w[i];
  return a;
}

}  // namespace robodamp::measfiles::detail
