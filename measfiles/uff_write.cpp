// Writing universal files (measfiles/uff.hpp) in the format's own columns.
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "measfiles/uff.hpp"

namespace robodamp::measfiles {

namespace {

std::string printf_line(const char* format, auto... args) {
  char b[256];
  std::snprintf(b, sizeof b, format, args...);
  return std::string(b) + "\n";
}

// 80A1 text: ASCII only (other bytes become ?), at most 80 columns, "NONE" when empty.
std::string text(const std::string& s, std::size_t width) {
  std::string out = s.empty() ? "NONE" : s;
  for (char& ch : out)
    if (static_cast<unsigned char>(ch) < 32 || static_cast<unsigned char>(ch) > 126) ch = '?';
  return out.substr(0, width);
}

std::string id_lines(const std::array<std::string, 5>& id) {
  std::string s;
  for (const auto& l : id) s += printf_line("%-80s", text(l, 80).c_str());
  return s;
}

std::string axis_line(const UffAxis& a) {
  return printf_line("%10d%5d%5d%5d %-20s %-20s", a.data_type, a.length_exp, a.force_exp, a.temperature_exp,
                     text(a.label, 20).c_str(), text(a.units, 20).c_str());
}

bool evenly_spaced(const std::vector<double>& x) {
  if (x.size() < 2) return false;
  const double step = (x.back() - x.front()) / static_cast<double>(x.size() - 1);
  if (!(step > 0.0)) return false;
  for (std::size_t k = 0; k < x.size(); ++k)
    if (std::abs(x[k] - (x.front() + static_cast<double>(k) * step)) > 1e-9 * std::abs(x.back())) return false;
  return true;
}

void put_double(std::string& out, double v) {
  unsigned char b[8];
  std::memcpy(b, &v, 8);
  if (std::endian::native == std::endian::big) std::swap_ranges(b, b + 4, std::reverse_iterator<unsigned char*>(b + 8));
  out.append(reinterpret_cast<const char*>(b), 8);
}

std::string function_dataset(const UffFunction& f, UffEncoding encoding) {
  if (f.x.size() != f.y.size() || f.x.empty())
    throw UffError("function '" + f.id[0] + "': " + std::to_string(f.x.size()) + " abscissa values for " +
                   std::to_string(f.y.size()) + " ordinate values");
  const bool binary = encoding == UffEncoding::kBinary;
  // ASCII keeps an even abscissa even (record 7 holds it); binary stores every abscissa value exactly.
  const bool even = !binary && evenly_spaced(f.x);
  const std::size_t n = f.x.size();
  std::vector<double> v;
  for (std::size_t k = 0; k < n; ++k) {
    if (!even) v.push_back(f.x[k]);
    v.push_back(f.y[k].real());
    if (f.is_complex) v.push_back(f.y[k].imag());
  }
  std::string data;
  if (binary) {
    for (double x : v) put_double(data, x);
  } else if (even) {  // 4E20.12
    for (std::size_t i = 0; i < v.size(); ++i)
      data += printf_line("%20.11E", v[i]).substr(0, 20) + ((i % 4 == 3 || i + 1 == v.size()) ? "\n" : "");
  } else {  // real: 2(E13.5,E20.12); complex: E13.5,2E20.12
    const std::size_t per = f.is_complex ? 3 : 2, per_line = f.is_complex ? 3 : 4;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const bool abscissa = i % per == 0;
      data += printf_line(abscissa ? "%13.5E" : "%20.11E", v[i]).substr(0, abscissa ? 13 : 20);
      if (i % per_line == per_line - 1 || i + 1 == v.size()) data += "\n";
    }
  }
  std::string s = printf_line("%6d", -1);
  if (binary) {
    s += printf_line("%6db%6d%6d%12d%12zu%6d%6d%12d%12d", 58, 1, 2, 11, data.size(), 0, 0, 0, 0);
  } else {
    s += printf_line("%6d", 58);
  }
  s += id_lines(f.id);
  s += printf_line("%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d", f.function_type, f.function_id, f.version, f.load_case,
                   text(f.response_entity, 10).c_str(), f.response_node, f.response_direction,
                   text(f.reference_entity, 10).c_str(), f.reference_node, f.reference_direction);
  const double step = even ? (f.x.back() - f.x.front()) / static_cast<double>(n - 1) : 0.0;
  s += printf_line("%10d%10zu%10d%13.5E%13.5E%13.5E", f.is_complex ? 6 : 4, n, even ? 1 : 0, even ? f.x.front() : 0.0,
                   step, f.z_value);
  s += axis_line(f.abscissa) + axis_line(f.ordinate) + axis_line(f.denominator) + axis_line(f.z_axis);
  s += data;
  return s + printf_line("%6d", -1);
}

std::string nodes_dataset(const std::vector<UffNode>& nodes) {
  std::string s = printf_line("%6d", -1) + printf_line("%6d", 15);
  for (const auto& n : nodes)
    s += printf_line("%10d%10d%10d%10d%13.5E%13.5E%13.5E", n.label, 0, 0, 11, n.xyz[0], n.xyz[1], n.xyz[2]);
  return s + printf_line("%6d", -1);
}

// Complex eigenvalue (analysis type 3), three translations per node, complex data.
std::string mode_dataset(const UffMode& m) {
  std::string s = printf_line("%6d", -1) + printf_line("%6d", 55) + id_lines(m.id);
  s += printf_line("%10d%10d%10d%10d%10d%10d", 1, 3, 2, 8, 5, 3);
  s += printf_line("%10d%10d%10d%10d", 2, 6, 1, m.number);
  s += printf_line("%13.5E%13.5E%13.5E%13.5E%13.5E%13.5E", m.eigenvalue.real(), m.eigenvalue.imag(), m.modal_a.real(),
                   m.modal_a.imag(), m.modal_b.real(), m.modal_b.imag());
  for (const auto& [node, v] : m.shape) {
    s += printf_line("%10d", node);
    s += printf_line("%13.5E%13.5E%13.5E%13.5E%13.5E%13.5E", v[0].real(), v[0].imag(), v[1].real(), v[1].imag(),
                     v[2].real(), v[2].imag());
  }
  return s + printf_line("%6d", -1);
}

}  // namespace

std::string format_uff(const UffFile& file, UffEncoding encoding) {
  std::string s;
  if (!file.nodes.empty()) s += nodes_dataset(file.nodes);
  for (const auto& f : file.functions) s += function_dataset(f, encoding);
  for (const auto& m : file.modes) s += mode_dataset(m);
  return s;
}

void write_uff(const std::string& path, const UffFile& file, UffEncoding encoding) {
  const std::string s = format_uff(file, encoding);
  std::ofstream out(path, std::ios::binary);
  out << s;
  if (!out.flush()) throw UffError(path + ": cannot be written");
}

}  // namespace robodamp::measfiles
