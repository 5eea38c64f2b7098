#include "measfiles/table.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace robodamp::measfiles {

namespace {

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

std::string unquoted(std::string s) {
  s = trim(s);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front())
    s = trim(s.substr(1, s.size() - 2));
  return s;
}

std::vector<std::string> split(const std::string& line, char delimiter) {
  std::vector<std::string> out;
  if (delimiter == ' ') {
    std::istringstream in(line);
    for (std::string w; in >> w;) out.push_back(w);
    return out;
  }
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, delimiter)) out.push_back(cell);
  if (!line.empty() && line.back() == delimiter) out.emplace_back();
  while (!out.empty() && trim(out.back()).empty()) out.pop_back();  // a trailing delimiter
  return out;
}

// A field as a number: "1.5", "-2e-3", "nan"; with a decimal comma "1,5" and "1.234,5" (a point then
// groups thousands). A field holding both marks the other way round is refused, not guessed.
bool number(std::string s, bool decimal_comma, double& v) {
  s = unquoted(s);
  if (s.empty()) return false;
  if (decimal_comma) {
    if (s.find(',') != std::string::npos) {
      if (s.find('.') != std::string::npos && s.find('.') > s.find(',')) return false;
      s.erase(std::remove(s.begin(), s.end(), '.'), s.end());
      std::replace(s.begin(), s.end(), ',', '.');
    }
  }
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE;
}

struct Layout {
  char delimiter{','};
  bool decimal_comma{false};
};

bool numeric_row(const std::string& line, const Layout& l, std::vector<double>* out) {
  const std::vector<std::string> f = split(line, l.delimiter);
  if (f.empty()) return false;
  std::vector<double> v;
  for (const auto& x : f) {
    double d = 0.0;
    if (!number(x, l.decimal_comma, d)) return false;
    v.push_back(d);
  }
  if (out != nullptr) *out = std::move(v);
  return true;
}

// The layout a data line is in: tab, then semicolon, then comma, then spaces; a comma inside the fields
// of the first, second and fourth is the decimal mark (whatever the first row holds).
std::optional<Layout> layout_of(const std::string& line) {
  std::vector<Layout> tries;
  if (line.find('\t') != std::string::npos) tries.push_back({'\t', true});
  if (line.find(';') != std::string::npos) tries.push_back({';', true});
  if (line.find(',') != std::string::npos) tries.push_back({',', false});
  tries.push_back({' ', true});
  for (const Layout& l : tries)
    if (numeric_row(line, l, nullptr)) return l;
  return std::nullopt;
}

// "Fx [N]", "Fx (kN)", "Fx in N" -> name, unit.
std::pair<std::string, std::string> name_and_unit(const std::string& field) {
  const std::string s = unquoted(field);
  for (const auto& [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
    const std::size_t a = s.rfind(open), b = s.rfind(close);
    if (a != std::string::npos && b != std::string::npos && b > a && b == s.size() - 1)
      return {trim(s.substr(0, a)), trim(s.substr(a + 1, b - a - 1))};
  }
  const std::size_t in = s.rfind(" in ");
  if (in != std::string::npos) return {trim(s.substr(0, in)), trim(s.substr(in + 4))};
  return {s, ""};
}

bool all_units(const std::vector<std::string>& fields) {
  for (const auto& f : fields) {
    const std::string u = unquoted(f);
    if (!u.empty() && !unit_scale(u.front() == '[' || u.front() == '(' ? u.substr(1, u.size() - 2) : u)) return false;
  }
  return true;
}

}  // namespace

std::string normalised(const std::string& name) {
  std::string s;
  for (char c : trim(name))
    s += c == ' ' || c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

Table parse_table(const std::string& text_in, const std::string& name) {
  std::string text = text_in;
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // UTF-8 byte-order mark
  std::vector<std::string> lines;
  {
    std::string line;
    std::istringstream in(text);
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines.push_back(line);
    }
  }
  Table t;
  std::optional<Layout> layout;
  std::vector<std::size_t> before;  // non-data lines before the first row (header, units row, preamble)
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string s = trim(lines[i]);
    if (s.empty() || s[0] == '#') continue;
    if (!layout) {
      layout = layout_of(s);
      if (!layout) {
        before.push_back(i);
        continue;
      }
      t.delimiter = layout->delimiter, t.decimal_comma = layout->decimal_comma;
    }
    std::vector<double> v;
    const std::vector<std::string> f = split(s, layout->delimiter);
    for (std::size_t k = 0; k < f.size(); ++k) {
      double d = 0.0;
      if (!number(f[k], layout->decimal_comma, d))
        throw std::invalid_argument(name + ":" + std::to_string(i + 1) + ": '" + unquoted(f[k]).substr(0, 40) +
                                    "' is not a number" + (unquoted(f[k]).empty() ? " (an empty field)" : ""));
      v.push_back(d);
    }
    if (t.columns == 0) t.columns = v.size();
    if (v.size() != t.columns)
      throw std::invalid_argument(name + ":" + std::to_string(i + 1) + ": " + std::to_string(v.size()) +
                                  " fields where the first row has " + std::to_string(t.columns));
    t.rows.push_back(std::move(v));
    t.lines.push_back(static_cast<int>(i + 1));
  }
  if (t.rows.empty()) throw std::invalid_argument(name + ": no rows of numbers");
  // The header: the last line before the data with as many fields (a units row may sit between).
  for (auto it = before.rbegin(); it != before.rend(); ++it) {
    const std::vector<std::string> f = split(trim(lines[*it]), layout->delimiter);
    if (f.size() != t.columns) continue;
    if (t.units.empty() && all_units(f) && it == before.rbegin()) {
      for (const auto& u : f) {
        std::string x = unquoted(u);
        if (!x.empty() && (x.front() == '[' || x.front() == '(')) x = x.substr(1, x.size() - 2);
        t.units.push_back(x);
      }
      continue;
    }
    std::vector<std::string> units;
    for (const auto& x : f) {
      auto [n, u] = name_and_unit(x);
      t.names.push_back(n), units.push_back(u);
    }
    if (t.units.empty()) t.units = units;
    t.header_line = static_cast<int>(*it + 1);
    break;
  }
  if (t.names.empty()) t.units.clear();
  return t;
}

Table read_table(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_table(s.str(), path);
}

std::vector<std::vector<double>> select_columns(const Table& t, const std::vector<ColumnSpec>& wanted,
                                                const std::string& name, const std::string& shown) {
  std::vector<std::size_t> index;
  std::vector<double> scale;
  for (const auto& w : wanted) {
    std::size_t at = index.size();
    if (!t.names.empty()) {
      at = t.names.size();
      for (std::size_t k = 0; k < t.names.size() && at == t.names.size(); ++k)
        if (std::find(w.names.begin(), w.names.end(), normalised(t.names[k])) != w.names.end()) at = k;
      if (at == t.names.size()) {
        std::string have;
        for (const auto& n : t.names) have += (have.empty() ? "" : ", ") + n;
        throw std::invalid_argument(name + ":" + std::to_string(t.header_line) + ": no column '" + w.names.front() +
                                    "' (the header has " + have + "); the columns are " + shown);
      }
    } else if (at >= t.columns) {
      throw std::invalid_argument(name + ": " + std::to_string(t.columns) + " columns and no header; the columns are " +
                                  shown);
    }
    double k = 1.0;
    const std::string unit = at < t.units.size() ? t.units[at] : "";
    if (!unit.empty() && w.quantity) {
      const auto u = unit_scale(unit);
      if (!u || u->quantity != *w.quantity)
        throw std::invalid_argument(name + ":" + std::to_string(t.header_line) + ": column '" + w.names.front() +
                                    "' is in '" + unit + "', not a unit of " + si_unit(*w.quantity) +
                                    " robodamp knows");
      k = u->to_si;
    }
    index.push_back(at), scale.push_back(k);
  }
  std::vector<std::vector<double>> out;
  for (const auto& r : t.rows) {
    std::vector<double> v;
    for (std::size_t i = 0; i < index.size(); ++i) v.push_back(r[index[i]] * scale[i]);
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace robodamp::measfiles
