#include "identify/recorded_signal.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "measfiles/table.hpp"
#include "measfiles/uff.hpp"
#include "measfiles/units.hpp"
#include "measfiles/wav.hpp"
#include "rt/recording.hpp"

namespace robodamp::identify {

namespace {

using measfiles::Quantity;

bool is_recording(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  return std::memcmp(magic, "RDAMPREC", 8) == 0;
}

milling::RecordedSignal from_recording(const std::string& path, std::string& described) {
  const rt::Recording rec = rt::read_recording(path);
  if (rec.frames.empty()) throw std::invalid_argument(path + ": the recording holds no frames");
  milling::RecordedSignal s;
  s.source = path, s.rate_hz = rec.header.at("rate_hz").get<double>(), s.unit = "m/s^2";
  const std::uint64_t first = rec.frames.front().tick;
  s.samples.assign(rec.frames.back().tick - first + 1, NAN);  // a missed tick: a dropout
  for (const auto& f : rec.frames) s.samples[f.tick - first] = f.accel_mps2;
  // The spindle speed the loop was told (set_spindle commands), held between them; none told: not known.
  bool told = false;
  for (const auto& f : rec.frames) told = told || rt::spindle_rpm_set(f).has_value();
  if (told) {
    double rpm = 0.0;
    s.rpm.assign(s.samples.size(), 0.0);
    std::size_t at = 0;
    for (const auto& f : rec.frames) {
      for (; at < f.tick - first; ++at) s.rpm[at] = rpm;
      if (const auto set = rt::spindle_rpm_set(f)) rpm = *set;
    }
    for (; at < s.rpm.size(); ++at) s.rpm[at] = rpm;
    s.rpm_from = "the recording's spindle commands";
  }
  described = "robodamp recording, the loop's accelerometer";
  return s;
}

milling::RecordedSignal from_sound(const std::string& path, const SignalOptions& o, std::string& described) {
  const measfiles::Sound snd = measfiles::read_sound(path, o.channel - 1);
  milling::RecordedSignal s;
  s.source = path, s.rate_hz = snd.rate_hz, s.samples = snd.samples;
  s.acceleration_mps2 = o.full_scale_mps2.has_value();
  s.unit = s.acceleration_mps2 ? "m/s^2" : "full scale";
  if (o.full_scale_mps2)
    for (double& v : s.samples) v *= *o.full_scale_mps2;
  char b[160];
  std::snprintf(b, sizeof b, "%s, channel %d of %d, peak %.3g of full scale", snd.format.c_str(), o.channel,
                snd.channels, snd.peak);
  described = b;
  return s;
}

milling::RecordedSignal from_uff(const std::string& path, const SignalOptions& o, std::string& described) {
  const measfiles::UffFile file = measfiles::read_uff(path);
  int found = 0;
  const measfiles::UffFunction* pick = nullptr;
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const auto& f = file.functions[i];
    if (o.record ? *o.record != static_cast<int>(i + 1) : f.function_type != measfiles::kUffTimeResponse) continue;
    if (o.response && !(f.response_node == o.response->node &&
                        (o.response->direction == 0 || o.response->direction == f.response_direction)))
      continue;
    ++found, pick = &f;
  }
  if (found != 1 || pick->is_complex || pick->x.size() < 2)
    throw std::invalid_argument(path + ": " + std::to_string(found) +
                                " time histories match; choose one with --record N or "
                                "--response NODE:DIR; the file holds:\n" +
                                describe_functions(file));
  milling::RecordedSignal s;
  s.source = path;
  double t_scale = 1.0;
  if (const auto u = measfiles::unit_scale(pick->abscissa.units); u && u->quantity == Quantity::kTime)
    t_scale = u->to_si;
  s.rate_hz = static_cast<double>(pick->x.size() - 1) / ((pick->x.back() - pick->x.front()) * t_scale);
  const auto u = measfiles::unit_scale(pick->ordinate.units);
  s.acceleration_mps2 =
      (u && u->quantity == Quantity::kAcceleration) || (!u && pick->ordinate.data_type == measfiles::kUffAcceleration);
  const double k = u && s.acceleration_mps2 ? u->to_si : 1.0;
  s.unit = s.acceleration_mps2 ? "m/s^2" : pick->ordinate.units;
  for (const auto& y : pick->y) s.samples.push_back(y.real() * k);
  described = "universal file, time history " + dof_text(pick->response_node, pick->response_direction) + " '" +
              pick->id[0] + "'";
  return s;
}

// A column by its name or 1-based number; nullopt when none.
std::optional<std::size_t> column_of(const measfiles::Table& t, const std::string& wanted) {
  char* end = nullptr;
  const long number = std::strtol(wanted.c_str(), &end, 10);
  if (*end == '\0' && number >= 1 && static_cast<std::size_t>(number) <= t.columns)
    return static_cast<std::size_t>(number - 1);
  for (std::size_t k = 0; k < t.names.size(); ++k)
    if (measfiles::normalised(t.names[k]) == measfiles::normalised(wanted)) return k;
  return std::nullopt;
}

milling::RecordedSignal from_table(const std::string& path, const SignalOptions& o, std::string& described) {
  const measfiles::Table t = measfiles::read_table(path);
  std::optional<std::size_t> time_col, value_col;
  for (std::size_t k = 0; k < t.names.size(); ++k) {
    const std::string n = measfiles::normalised(t.names[k]);
    if (n == "time" || n == "t" || n == "time_s" || n == "t_s" || n == "zeit") time_col = k;
  }
  if (!o.column.empty()) {
    value_col = column_of(t, o.column);
    if (!value_col)
      throw std::invalid_argument(path + ": no column '" + o.column + "' (a name in the header or 1 .. " +
                                  std::to_string(t.columns) + ")");
  } else {
    value_col = time_col == std::size_t{0} && t.columns > 1 ? 1 : 0;
  }
  if (!time_col && t.names.empty() && !o.rate_hz && t.columns > 1 && *value_col != 0)
    time_col = 0;  // no header: time first
  milling::RecordedSignal s;
  s.source = path;
  std::string unit = *value_col < t.units.size() ? t.units[*value_col] : "";
  if (unit.empty() && *value_col < t.names.size()) {  // a unit in the name, robodamp's way: accel_mps2
    const std::string n = measfiles::normalised(t.names[*value_col]);
    if (n.size() > 5 && n.compare(n.size() - 5, 5, "_mps2") == 0) unit = "m/s^2";
  }
  const auto u = measfiles::unit_scale(unit);
  s.acceleration_mps2 = u && u->quantity == Quantity::kAcceleration;
  s.unit = s.acceleration_mps2 ? "m/s^2" : unit;
  for (const auto& r : t.rows) s.samples.push_back(r[*value_col] * (s.acceleration_mps2 ? u->to_si : 1.0));
  if (!o.rpm_column.empty()) {
    const auto c = column_of(t, o.rpm_column);
    if (!c) throw std::invalid_argument(path + ": no spindle-speed column '" + o.rpm_column + "'");
    for (const auto& r : t.rows) s.rpm.push_back(r[*c]);
    s.rpm_from = "the column '" + (*c < t.names.size() ? t.names[*c] : std::to_string(*c + 1)) + "'";
  }
  if (o.rate_hz) {
    s.rate_hz = *o.rate_hz;
  } else if (time_col) {
    double k = 1.0;
    if (const auto tu = measfiles::unit_scale(*time_col < t.units.size() ? t.units[*time_col] : "");
        tu && tu->quantity == Quantity::kTime)
      k = tu->to_si;
    const double dt =
        (t.rows.back()[*time_col] - t.rows.front()[*time_col]) * k / static_cast<double>(t.rows.size() - 1);
    for (std::size_t i = 1; i < t.rows.size(); ++i)
      if (!(std::abs((t.rows[i][*time_col] - t.rows[i - 1][*time_col]) * k - dt) <= 0.01 * dt))
        throw std::invalid_argument(path + ":" + std::to_string(t.lines[i]) +
                                    ": the time step changes (a constant sample rate is needed)");
    s.rate_hz = 1.0 / dt;
  } else {
    throw std::invalid_argument(path + ": no time column (time, t, time_s, t_s, zeit): give --rate-hz");
  }
  described = "table, column " +
              (*value_col < t.names.size() ? "'" + t.names[*value_col] + "'" : std::to_string(*value_col + 1)) +
              (unit.empty() ? std::string(", no unit") : ", in " + unit);
  return s;
}

}  // namespace

milling::RecordedSignal read_recorded_signal(const std::string& path, const SignalOptions& o, std::string& described) {
  if (!std::ifstream(path)) throw std::invalid_argument(path + ": cannot be read");
  if (is_recording(path)) return from_recording(path, described);
  if (measfiles::looks_like_sound(path)) return from_sound(path, o, described);
  if (looks_like_uff(path)) return from_uff(path, o, described);
  return from_table(path, o, described);
}

}  // namespace robodamp::identify
