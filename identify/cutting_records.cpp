#include "identify/cutting_records.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "measfiles/table.hpp"

namespace robodamp::identify {

namespace {

namespace fs = std::filesystem;

struct Revolution {
  std::size_t begin{0}, end{0};  // samples [begin, end)
  std::array<double, 3> mean{};
  double fluctuation_n{0.0};  // within-revolution standard deviation, all axes together
  double centre_s{0.0};
};

std::vector<Revolution> revolutions(const ForceRecord& r, double period_s) {
  std::vector<Revolution> out;
  const double per = period_s * r.fs_hz;
  for (int k = 0;; ++k) {
    const auto b = static_cast<std::size_t>(std::lround(k * per)),
               e = static_cast<std::size_t>(std::lround((k + 1) * per));
    if (e > r.t_s.size()) break;
    Revolution v;
    v.begin = b, v.end = e;
    const double n = static_cast<double>(e - b);
    double var = 0.0;
    for (int a = 0; a < 3; ++a) {
      double sum = 0.0, sq = 0.0;
      for (std::size_t i = b; i < e; ++i) sum += r.f_n[static_cast<std::size_t>(a)][i];
      v.mean[static_cast<std::size_t>(a)] = sum / n;
      for (std::size_t i = b; i < e; ++i) sq += std::pow(r.f_n[static_cast<std::size_t>(a)][i] - sum / n, 2);
      var += sq / n;
    }
    v.fluctuation_n = std::sqrt(var);
    v.centre_s = 0.5 * (r.t_s[b] + r.t_s[e - 1]);
    out.push_back(v);
  }
  return out;
}

// The variance share of the revolution-synchronous average over revolutions [b, e).
double periodic_share(const ForceRecord& r, const std::vector<Revolution>& revs, std::size_t b, std::size_t e) {
  std::size_t len = revs[b].end - revs[b].begin;
  for (std::size_t k = b; k < e; ++k) len = std::min(len, revs[k].end - revs[k].begin);
  double periodic = 0.0, total = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto& f = r.f_n[a];
    double mean = 0.0;
    for (std::size_t k = b; k < e; ++k)
      for (std::size_t i = 0; i < len; ++i) mean += f[revs[k].begin + i];
    mean /= static_cast<double>((e - b) * len);
    for (std::size_t i = 0; i < len; ++i) {
      double avg = 0.0;
      for (std::size_t k = b; k < e; ++k) avg += f[revs[k].begin + i] / static_cast<double>(e - b);
      periodic += (avg - mean) * (avg - mean) * static_cast<double>(e - b);
      for (std::size_t k = b; k < e; ++k) total += std::pow(f[revs[k].begin + i] - mean, 2);
    }
  }
  return total > 0.0 ? periodic / total : 0.0;
}

double magnitude(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// The mean of the revolutions' means in [b, e) and its time.
std::pair<std::array<double, 3>, double> average(const std::vector<Revolution>& revs, std::size_t b, std::size_t e) {
  std::array<double, 3> m{};
  double t = 0.0;
  for (std::size_t k = b; k < e; ++k) {
    for (std::size_t a = 0; a < 3; ++a) m[a] += revs[k].mean[a] / static_cast<double>(e - b);
    t += revs[k].centre_s / static_cast<double>(e - b);
  }
  return {m, t};
}

// The offset and drift from the air before and after the cut: a line through both, a constant from one.
void remove_drift(std::vector<Revolution>& revs, const std::vector<bool>& air, std::size_t first_cut,
                  std::size_t last_cut, SteadyCut& out) {
  std::size_t b0 = first_cut, e1 = last_cut + 1;
  while (b0 > 0 && air[b0 - 1]) --b0;
  while (e1 < revs.size() && air[e1]) ++e1;
  const bool before = b0<first_cut, after = e1> last_cut + 1;
  if (!before && !after) {
    out.drift_from = "none: the record holds no air cut, its offset and drift stay in the means";
    return;
  }
  const auto [m0, t0] = before ? average(revs, b0, first_cut) : average(revs, last_cut + 1, e1);
  const auto [m1, t1] = after ? average(revs, last_cut + 1, e1) : std::pair{m0, t0};
  for (std::size_t a = 0; a < 3; ++a) {
    out.drift_n_per_s[a] = before && after && t1 > t0 ? (m1[a] - m0[a]) / (t1 - t0) : 0.0;
    out.offset_n[a] = m0[a] - out.drift_n_per_s[a] * t0;  // at t = 0
  }
  for (auto& v : revs)
    for (std::size_t a = 0; a < 3; ++a) v.mean[a] -= out.offset_n[a] + out.drift_n_per_s[a] * v.centre_s;
  out.drift_from = before && after ? "the air before and after the cut (offset and linear drift)"
                   : before        ? "the air before the cut (offset only)"
                                   : "the air after the cut (offset only)";
}

}  // namespace

AxisMap parse_axes(const std::string& text) {
  AxisMap m;
  std::istringstream in(text);
  std::string part;
  std::array<bool, 3> used{};
  for (std::size_t k = 0; k < 3; ++k) {
    if (!std::getline(in, part, ','))
      throw std::invalid_argument("--axes '" + text + "': three of fx, fy, fz with signs, e.g. -fy,fx,fz");
    double sign = 1.0;
    if (!part.empty() && (part[0] == '-' || part[0] == '+')) sign = part[0] == '-' ? -1.0 : 1.0, part.erase(0, 1);
    const int column = part == "fx" ? 0 : part == "fy" ? 1 : part == "fz" ? 2 : -1;
    if (column < 0 || used[static_cast<std::size_t>(column)])
      throw std::invalid_argument("--axes '" + text + "': each of fx, fy, fz once, a sign optional, e.g. -fy,fx,fz");
    used[static_cast<std::size_t>(column)] = true;
    m.column[k] = column, m.sign[k] = sign;
  }
  if (std::getline(in, part, ',')) throw std::invalid_argument("--axes '" + text + "': three of fx, fy, fz");
  return m;
}

ForceRecord read_force_record(const std::string& path) {
  const measfiles::Table t = measfiles::read_table(path);
  using measfiles::Quantity;
  const std::vector<measfiles::ColumnSpec> wanted = {{{"time", "t", "time_s", "zeit"}, Quantity::kTime},
                                                     {{"fx", "fx_n", "force_x", "f_x"}, Quantity::kForce},
                                                     {{"fy", "fy_n", "force_y", "f_y"}, Quantity::kForce},
                                                     {{"fz", "fz_n", "force_z", "f_z"}, Quantity::kForce}};
  const auto rows =
      measfiles::select_columns(t, wanted, path, "time, Fx, Fy, Fz (by name, or in that order without a header)");
  ForceRecord r;
  r.source = path;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (double v : rows[i])
      if (!std::isfinite(v))
        throw std::invalid_argument(path + ":" + std::to_string(t.lines[i]) + ": a value is not a finite number");
    r.t_s.push_back(rows[i][0]);
    for (std::size_t a = 0; a < 3; ++a) r.f_n[a].push_back(rows[i][a + 1]);
  }
  if (r.t_s.size() < 64)
    throw std::invalid_argument(path + ": too few samples (" + std::to_string(r.t_s.size()) + ", at least 64)");
  // The first step against every other (time written to a few digits: a thousandth of a step tolerated),
  // then the rate from the whole record.
  const double step = r.t_s[1] - r.t_s[0];
  if (!(step > 0.0))
    throw std::invalid_argument(path + ":" + std::to_string(t.lines[1]) + ": the time does not increase");
  for (std::size_t i = 1; i < r.t_s.size(); ++i)
    if (!(std::abs(r.t_s[i] - r.t_s[i - 1] - step) <= 1e-2 * step))
      throw std::invalid_argument(path + ":" + std::to_string(t.lines[i]) +
                                  ": the time step changes (a constant sample rate is needed)");
  r.fs_hz = static_cast<double>(r.t_s.size() - 1) / (r.t_s.back() - r.t_s.front());
  return r;
}

namespace {

// The longest run [begin, end) of consecutive indices in [b, e) where holds(index); the first of equal runs.
template <class Holds>
std::pair<std::size_t, std::size_t> longest_run(std::size_t b, std::size_t e, Holds holds) {
  std::size_t best_b = 0, best_e = 0;
  for (std::size_t k = b; k < e;) {
    if (!holds(k)) {
      ++k;
      continue;
    }
    std::size_t end = k;
    while (end < e && holds(end)) ++end;
    if (end - k > best_e - best_b) best_b = k, best_e = end;
    k = end;
  }
  return {best_b, best_e};
}

}  // namespace

SteadyCut steady_cut(const ForceRecord& r, double spindle_rpm, double feed_per_tooth_mm, const RecordSettings& s) {
  if (!(spindle_rpm > 0.0 && spindle_rpm <= 200000.0))
    throw std::invalid_argument(r.source + ": spindle speed " + std::to_string(spindle_rpm) +
                                " rpm: allowed 0 < value <= 200000 rpm");
  const double period_s = 60.0 / spindle_rpm;
  if (period_s * r.fs_hz < 8.0)
    throw std::invalid_argument(r.source + ": " + std::to_string(r.fs_hz) + " Hz samples a revolution of " +
                                std::to_string(spindle_rpm) + " rpm fewer than 8 times");
  std::vector<Revolution> revs = revolutions(r, period_s);
  if (revs.size() < 5)
    throw std::invalid_argument(r.source + ": " + std::to_string(revs.size()) +
                                " revolutions recorded, at least 5 needed");
  // Air: the quietest revolutions (their fluctuation is the noise); cutting: three times that or more.
  std::vector<double> fl;
  for (const auto& v : revs) fl.push_back(v.fluctuation_n);
  std::sort(fl.begin(), fl.end());
  const double quiet = fl[fl.size() / 10];
  std::vector<bool> cutting(revs.size()), air(revs.size());
  std::size_t count = 0;
  for (std::size_t k = 0; k < revs.size(); ++k)
    cutting[k] = revs[k].fluctuation_n > 3.0 * quiet, air[k] = revs[k].fluctuation_n < 2.0 * quiet, count += cutting[k];
  if (count < 3) {  // no air in the record: every revolution cuts
    std::fill(cutting.begin(), cutting.end(), true), std::fill(air.begin(), air.end(), false);
  }
  // The longest run of cutting revolutions.
  const auto [best_b, best_e] = longest_run(0, revs.size(), [&](std::size_t k) { return cutting[k]; });
  SteadyCut out;
  out.cutting_revolutions = static_cast<int>(best_e - best_b);
  remove_drift(revs, air, best_b, best_e - 1, out);
  // Steady: the revolutions whose means agree with the run's median, within 2 % of its magnitude and
  // four times the noise a revolution's mean keeps.
  std::array<double, 3> median{};
  for (std::size_t a = 0; a < 3; ++a) {
    std::vector<double> m;
    for (std::size_t k = best_b; k < best_e; ++k) m.push_back(revs[k].mean[a]);
    std::nth_element(m.begin(), m.begin() + static_cast<long>(m.size() / 2), m.end());
    median[a] = m[m.size() / 2];
  }
  const double per = period_s * r.fs_hz;
  const double tol = 0.02 * magnitude(median) + 4.0 * quiet / std::sqrt(per);
  auto [sb, se] = longest_run(best_b, best_e, [&](std::size_t j) {
    return magnitude({revs[j].mean[0] - median[0], revs[j].mean[1] - median[1], revs[j].mean[2] - median[2]}) <= tol;
  });
  if (se - sb >= 5) ++sb, --se;  // the entry's and the exit's last partial engagement
  if (se - sb < 3)
    throw std::invalid_argument(r.source + ": no steady cut of 3 revolutions or more (" +
                                std::to_string(best_e - best_b) + " revolutions cut, their means differ by more than " +
                                std::to_string(tol) + " N)");
  out.periodic_share = periodic_share(r, revs, sb, se);
  if (out.periodic_share < kMinPeriodicShare) {
    char b[200];
    std::snprintf(
        b, sizeof b,
        ": %.0f %% of the force's variance repeats with each revolution of %.6g rpm (at least %.0f %% for a cut): "
        "no cutting at that speed (is the spindle speed right? is the record a cut?)",
        100.0 * out.periodic_share, spindle_rpm, 100.0 * kMinPeriodicShare);
    throw std::invalid_argument(r.source + b);
  }
  const auto [m, t] = average(revs, sb, se);
  (void)t;
  for (std::size_t k = sb; k < se; ++k)
    out.spread_pct = std::max(
        out.spread_pct, 100.0 * magnitude({revs[k].mean[0] - m[0], revs[k].mean[1] - m[1], revs[k].mean[2] - m[2]}) /
                            std::max(magnitude(m), 1e-12));
  std::array<double, 3> tool{};
  for (std::size_t k = 0; k < 3; ++k)
    tool[k] = (s.force_on_workpiece ? -1.0 : 1.0) * s.axes.sign[k] * m[static_cast<std::size_t>(s.axes.column[k])];
  out.means = {feed_per_tooth_mm, tool[0], tool[1], tool[2]};
  out.start_s = r.t_s[revs[sb].begin], out.end_s = r.t_s[revs[se - 1].end - 1] + 1.0 / r.fs_hz;
  out.revolutions = static_cast<int>(se - sb);
  return out;
}

std::vector<RecordTest> read_record_tests(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot be read");
  std::vector<RecordTest> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const char delimiter = line.find('\t') != std::string::npos  ? '\t'
                           : line.find(';') != std::string::npos ? ';'
                                                                 : ',';
    std::vector<std::string> f;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, delimiter);) {
      const std::size_t a = cell.find_first_not_of(" \t\""), b = cell.find_last_not_of(" \t\"");
      f.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
    }
    if (f.size() >= 1 && (f[0] == "file" || f[0] == "File")) continue;  // the header
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (f.size() < 3) throw std::invalid_argument(where + "file, feed_per_tooth_mm, spindle_rpm expected");
    auto value = [&](std::string v, const char* what) {
      if (delimiter != ',') std::replace(v.begin(), v.end(), ',', '.');
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !std::isfinite(x) || !(x > 0.0))
        throw std::invalid_argument(where + what + " '" + v + "' is not a number > 0");
      return x;
    };
    RecordTest t;
    t.file = (fs::path(f[0]).is_absolute() ? fs::path(f[0]) : fs::path(path).parent_path() / f[0]).string();
    t.feed_per_tooth_mm = value(f[1], "feed per tooth (mm)");
    t.spindle_rpm = value(f[2], "spindle speed (rpm)");
    out.push_back(t);
  }
  if (out.empty()) throw std::invalid_argument(path + ": no tests (lines of file, feed_per_tooth_mm, spindle_rpm)");
  return out;
}

}  // namespace robodamp::identify
