// Reading universal files (measfiles/uff.hpp): the file is a run of datasets, each between two lines
// holding -1; the line after the first -1 holds the dataset's number (a trailing b: binary data follows
// its ASCII records). Records are read by the format's fixed columns first and by free spacing second.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "measfiles/uff.hpp"
#include "measfiles/uff_fields.hpp"

namespace robodamp::measfiles {

namespace {

using detail::Context;
using detail::numbers_in;
using detail::trimmed;

struct Cursor {
  const std::string& bytes;
  std::size_t pos{0};
  int line{0};

  bool next(std::string& out) {
    if (pos >= bytes.size()) return false;
    const std::size_t end = bytes.find('\n', pos);
    out = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (!out.empty() && out.back() == '\r') out.pop_back();
    pos = end == std::string::npos ? bytes.size() : end + 1;
    ++line;
    return true;
  }
};

bool is_end(const std::string& line) { return trimmed(line) == "-1"; }

UffAxis read_axis(const std::string& line, const Context& c, int record) {
  UffAxis a;
  const detail::AxisFields f = detail::axis_fields(line, c, record);
  a.data_type = f.ints[0], a.length_exp = f.ints[1], a.force_exp = f.ints[2], a.temperature_exp = f.ints[3];
  a.label = f.label, a.units = f.units;
  return a;
}

// The values of record 12 (binary): n elements of 4 or 8 bytes in the file's byte order.
std::vector<double> binary_values(const std::string& data, std::size_t element, bool big_endian, const Context& c) {
  std::vector<double> out;
  out.reserve(data.size() / element);
  for (std::size_t i = 0; i + element <= data.size(); i += element) {
    unsigned char b[8];
    std::memcpy(b, data.data() + i, element);
    if (big_endian != (std::endian::native == std::endian::big))
      for (std::size_t k = 0; k < element / 2; ++k) std::swap(b[k], b[element - 1 - k]);
    if (element == 8) {
      double v = 0.0;
      std::memcpy(&v, b, 8);
      out.push_back(v);
    } else {
      float v = 0.0f;
      std::memcpy(&v, b, 4);
      out.push_back(v);
    }
  }
  if (out.size() * element != data.size())
    throw UffError(c.where(12) + std::to_string(data.size()) + " bytes is not a whole number of " +
                   std::to_string(element) + "-byte values");
  return out;
}

void fill_values(UffFunction& f, const std::vector<double>& v, std::size_t n, double min, double step,
                 const Context& c) {
  const std::size_t per_point = (f.is_complex ? 2 : 1) + (f.even ? 0 : 1);
  if (v.size() != n * per_point)
    throw UffError(c.where(12) + std::to_string(n * per_point) + " values expected (" + std::to_string(n) +
                   " points, " + (f.is_complex ? "complex" : "real") + ", " + (f.even ? "even" : "uneven") +
                   " abscissa), found " + std::to_string(v.size()));
  f.x.resize(n), f.y.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double* p = v.data() + k * per_point;
    if (f.even) {
      f.x[k] = min + static_cast<double>(k) * step;
    } else {
      f.x[k] = *p++;
    }
    f.y[k] = f.is_complex ? std::complex<double>(p[0], p[1]) : std::complex<double>(p[0], 0.0);
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(f.x[k]) || !std::isfinite(f.y[k].real()) || !std::isfinite(f.y[k].imag()))
      throw UffError(c.where(12) + "point " + std::to_string(k + 1) + " is not a finite number");
}

// Dataset 58: records 1-11 in ASCII, then record 12 in ASCII (data_lines) or binary (data_bytes).
UffFunction read_function(const std::vector<std::string>& ascii, const std::vector<std::string>& data_lines,
                          const std::string* data_bytes, bool big_endian, const Context& c) {
  if (ascii.size() < 11)
    throw UffError(c.where(0) + "11 header records expected, found " + std::to_string(ascii.size()));
  UffFunction f;
  for (int i = 0; i < 5; ++i) f.id[i] = trimmed(ascii[i]);
  auto at = [&](int record) {  // the record's own line (binary data has none)
    Context rc = c;
    rc.line = c.line + record;
    return rc;
  };
  const detail::Record6 r6 = detail::record6_fields(ascii[5], at(6));
  f.function_type = r6.ints[0], f.function_id = r6.ints[1], f.version = r6.ints[2], f.load_case = r6.ints[3];
  f.response_entity = r6.response_entity, f.response_node = r6.ints[4], f.response_direction = r6.ints[5];
  f.reference_entity = r6.reference_entity, f.reference_node = r6.ints[6], f.reference_direction = r6.ints[7];
  const detail::Record7 r7 = detail::record7_fields(ascii[6], at(7));
  const int type = r7.ordinate_type;
  if (type != 2 && type != 4 && type != 5 && type != 6)
    throw UffError(at(7).where(7) + "field 1 (ordinate data type) = " + std::to_string(type) +
                   ": allowed 2 (real single), 4 (real double), 5 (complex single), 6 (complex double)");
  if (r7.points <= 0 || r7.points > 100'000'000)
    throw UffError(at(7).where(7) + "field 2 (number of values) = " + std::to_string(r7.points) + ": allowed 1 .. 1e8");
  if (r7.spacing != 0 && r7.spacing != 1)
    throw UffError(at(7).where(7) + "field 3 (abscissa spacing) = " + std::to_string(r7.spacing) +
                   ": allowed 0 (uneven), 1 (even)");
  f.is_complex = type >= 5, f.double_precision = type == 4 || type == 6, f.even = r7.spacing == 1;
  f.z_value = r7.z_value;
  if (f.even && !(std::isfinite(r7.min) && std::isfinite(r7.step) && r7.step > 0.0))
    throw UffError(at(7).where(7) + "field 5 (abscissa increment) = " + detail::shown(r7.step) +
                   ": an even abscissa needs a step > 0");
  f.abscissa = read_axis(ascii[7], at(8), 8), f.ordinate = read_axis(ascii[8], at(9), 9);
  f.denominator = read_axis(ascii[9], at(10), 10), f.z_axis = read_axis(ascii[10], at(11), 11);
  const auto n = static_cast<std::size_t>(r7.points);
  std::vector<double> values;
  if (data_bytes != nullptr) {
    values = binary_values(*data_bytes, f.double_precision ? 8 : 4, big_endian, c);
  } else {
    for (std::size_t i = 0; i < data_lines.size(); ++i) {
      Context line_context = c;
      line_context.line = c.line + 12 + static_cast<int>(i);
      numbers_in(data_lines[i], values, line_context);
    }
  }
  fill_values(f, values, n, r7.min, r7.step, c);
  return f;
}

std::vector<UffNode> read_nodes_15(const std::vector<std::string>& lines, const Context& c) {
  std::vector<UffNode> out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    Context lc = c;
    lc.line = c.line + static_cast<int>(i);
    std::vector<double> v;
    numbers_in(lines[i], v, lc);
    if (v.empty()) continue;
    if (v.size() != 7)
      throw UffError(lc.where(1) + "a node needs 7 fields (label, 3 systems and colour, x, y, z), found " +
                     std::to_string(v.size()));
    out.push_back({static_cast<int>(v[0]), {v[4], v[5], v[6]}});
  }
  return out;
}

std::vector<UffNode> read_nodes_2411(const std::vector<std::string>& lines, const Context& c) {
  std::vector<UffNode> out;
  for (std::size_t i = 0; i + 1 < lines.size(); i += 2) {
    Context lc = c;
    lc.line = c.line + static_cast<int>(i);
    std::vector<double> a, b;
    numbers_in(lines[i], a, lc);
    lc.line += 1;
    numbers_in(lines[i + 1], b, lc);
    if (a.size() != 4 || b.size() != 3) throw UffError(lc.where(2) + "a node needs 4 integers, then 3 coordinates");
    out.push_back({static_cast<int>(a[0]), {b[0], b[1], b[2]}});
  }
  return out;
}

std::vector<double> numbers_of(const std::string& line, const Context& c, int record, std::size_t at_least) {
  std::vector<double> v;
  numbers_in(line, v, c);
  if (v.size() < at_least)
    throw UffError(c.where(record) + std::to_string(at_least) + " fields expected, found " + std::to_string(v.size()));
  return v;
}

// Dataset 55: normal modes (analysis type 2, real) or complex eigenvalues (3), three translations per node.
UffMode read_mode(const std::vector<std::string>& lines, const Context& c) {
  if (lines.size() < 8)
    throw UffError(c.where(0) + "at least 8 records expected, found " + std::to_string(lines.size()));
  UffMode m;
  for (int i = 0; i < 5; ++i) m.id[i] = trimmed(lines[i]);
  const std::vector<double> r6 = numbers_of(lines[5], c, 6, 6);
  const int analysis = static_cast<int>(r6[1]), characteristic = static_cast<int>(r6[2]),
            data_type = static_cast<int>(r6[4]);
  const auto ndv = static_cast<std::size_t>(r6[5]);
  if (analysis != 2 && analysis != 3)
    throw UffError(c.where(6) + "field 2 (analysis type) = " + std::to_string(analysis) +
                   ": allowed 2 (normal mode), 3 (complex eigenvalue)");
  if ((characteristic != 2 && characteristic != 3) || ndv < 3 || ndv > 6)
    throw UffError(c.where(6) + "fields 3 and 6 (data characteristic, values per node): allowed 3 or 6 DOF per node");
  const bool complex_data = data_type == 5;
  const std::vector<double> r7 = numbers_of(lines[6], c, 7, 4);
  m.number = static_cast<int>(r7[3]);
  const std::vector<double> r8 = numbers_of(lines[7], c, 8, analysis == 3 ? 6 : 4);
  if (analysis == 3) {
    m.eigenvalue = {r8[0], r8[1]}, m.modal_a = {r8[2], r8[3]}, m.modal_b = {r8[4], r8[5]};
  } else {
    const double wn = 2.0 * M_PI * r8[0], zeta = r8[2];
    m.eigenvalue = {-zeta * wn, wn * std::sqrt(std::max(0.0, 1.0 - zeta * zeta))}, m.modal_a = {r8[1], 0.0};
  }
  const std::size_t per_node = ndv * (complex_data ? 2 : 1);
  for (std::size_t i = 8; i < lines.size();) {
    Context lc = c;
    lc.line = c.line + static_cast<int>(i);
    std::vector<double> node;
    numbers_in(lines[i++], node, lc);
    if (node.empty()) continue;
    std::vector<double> v;
    while (v.size() < per_node && i < lines.size()) numbers_in(lines[i++], v, lc);
    if (v.size() != per_node) throw UffError(lc.where(10) + std::to_string(per_node) + " values per node expected");
    std::array<std::complex<double>, 3> s{};
    for (std::size_t k = 0; k < 3; ++k) s[k] = complex_data ? std::complex<double>(v[2 * k], v[2 * k + 1]) : v[k];
    m.shape.emplace_back(static_cast<int>(node[0]), s);
  }
  return m;
}

struct Header {
  int number{0};
  bool binary{false};
  bool big_endian{false};
  long long bytes{0};
  int ascii_lines{11};
};

Header read_header(const std::string& line, const Context& c) {
  Header h;
  const std::string t = trimmed(line);
  std::size_t used = 0;
  try {
    h.number = std::stoi(t, &used);
  } catch (const std::exception&) {
    throw UffError(c.where(0) + "'" + t.substr(0, 20) + "' is not a dataset number");
  }
  if (used < t.size() && (t[used] == 'b' || t[used] == 'B')) {
    h.binary = true;
    std::vector<double> v;
    numbers_in(t.substr(used + 1), v, c);
    if (v.size() < 4)
      throw UffError(c.where(0) + "a binary dataset's header needs byte order, float format, lines and bytes");
    const int order = static_cast<int>(v[0]), format = static_cast<int>(v[1]);
    if (order != 1 && order != 2)
      throw UffError(c.where(0) + "field 3 (byte ordering) = " + std::to_string(order) +
                     ": allowed 1 (little-endian), 2 (big-endian)");
    if (format != 2)
      throw UffError(c.where(0) + "field 4 (floating point format) = " + std::to_string(format) +
                     ": only 2 (IEEE 754) is read");
    h.big_endian = order == 2, h.ascii_lines = static_cast<int>(v[2]), h.bytes = static_cast<long long>(v[3]);
    if (h.ascii_lines != 11 || h.bytes < 0)
      throw UffError(c.where(0) + "fields 5 and 6 (ASCII lines, bytes) = " + std::to_string(h.ascii_lines) + ", " +
                     std::to_string(h.bytes) + ": 11 lines and a byte count >= 0 expected");
  }
  return h;
}

}  // namespace

UffFile parse_uff(const std::string& bytes, const std::string& name) {
  UffFile out;
  Cursor cur{bytes};
  std::string line;
  int index = 0;
  while (cur.next(line)) {
    if (trimmed(line).empty()) continue;
    if (!is_end(line))
      throw UffError(name + ":" + std::to_string(cur.line) + ": a dataset opens with a line holding -1, found '" +
                     trimmed(line).substr(0, 40) + "'");
    Context c{name, ++index, 0, cur.line + 1};
    if (!cur.next(line)) throw UffError(c.where(0) + "the file ends after -1");
    const Header h = read_header(line, c);
    c.dataset = h.number;
    std::vector<std::string> lines;
    std::string data;
    bool closed = false;
    if (h.binary) {
      if (h.number != 58)
        throw UffError(c.where(0) + "binary dataset " + std::to_string(h.number) + " is not read (58b is)");
      for (int i = 0; i < h.ascii_lines; ++i)
        if (cur.next(line)) lines.push_back(line);
      if (cur.pos + static_cast<std::size_t>(h.bytes) > bytes.size())
        throw UffError(c.where(12) + "the header announces " + std::to_string(h.bytes) + " bytes, the file holds " +
                       std::to_string(bytes.size() - cur.pos));
      data = bytes.substr(cur.pos, static_cast<std::size_t>(h.bytes));
      cur.pos += static_cast<std::size_t>(h.bytes);
    }
    while (cur.next(line)) {
      if (is_end(line)) {
        closed = true;
        break;
      }
      if (h.binary && !trimmed(line).empty()) throw UffError(c.where(12) + "data after the announced bytes");
      if (!h.binary) lines.push_back(line);
    }
    if (!closed) throw UffError(c.where(0) + "the dataset is not closed with -1");
    if (h.number == 58) {
      const std::vector<std::string> head(lines.begin(), lines.begin() + std::min<std::size_t>(11, lines.size()));
      const std::vector<std::string> rest(lines.begin() + static_cast<long>(head.size()), lines.end());
      UffFunction f = read_function(head, rest, h.binary ? &data : nullptr, h.big_endian, c);
      f.dataset_index = index, f.line = c.line, f.binary = h.binary;
      out.functions.push_back(std::move(f));
    } else if (h.number == 15) {
      for (auto& n : read_nodes_15(lines, c)) out.nodes.push_back(n);
    } else if (h.number == 2411) {
      for (auto& n : read_nodes_2411(lines, c)) out.nodes.push_back(n);
    } else if (h.number == 55) {
      out.modes.push_back(read_mode(lines, c));
    } else {
      out.skipped_datasets.push_back(h.number);
    }
  }
  if (index == 0) throw UffError(name + ": no dataset (a universal file holds datasets between lines of -1)");
  return out;
}

UffFile read_uff(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UffError(path + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_uff(s.str(), path);
}

}  // namespace robodamp::measfiles
