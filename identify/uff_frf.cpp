#include "identify/uff_frf.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "measfiles/units.hpp"

namespace robodamp::identify {

namespace {

using measfiles::Quantity;
using measfiles::UffFunction;

constexpr double kTwoPi = 2.0 * M_PI;

std::optional<Quantity> quantity_of_type(int data_type) {
  switch (data_type) {
    case measfiles::kUffDisplacement:
      return Quantity::kLength;
    case measfiles::kUffVelocity:
      return Quantity::kVelocity;
    case measfiles::kUffAcceleration:
      return Quantity::kAcceleration;
    case measfiles::kUffExcitationForce:
    case measfiles::kUffReactionForce:
      return Quantity::kForce;
    default:
      return std::nullopt;
  }
}

std::string known(const std::string& label) { return label.empty() || label == "NONE" ? "" : label; }

// The scale of one axis: its unit label when robodamp knows it (checked against its data type), else SI
// by its data type. what: "ordinate" or "denominator".
measfiles::UnitScale axis_scale(const std::string& label, int data_type, std::optional<Quantity> fallback, int record,
                                const char* what) {
  const auto by_type = quantity_of_type(data_type);
  if (const auto u = measfiles::unit_scale(label)) {
    if (by_type && *by_type != u->quantity)
      throw std::invalid_argument("record " + std::to_string(record) + ": the " + what + " unit '" + label +
                                  "' is not a unit of the data type " + std::to_string(data_type) + " (" +
                                  measfiles::si_unit(*by_type) + ")");
    return *u;
  }
  if (!known(label).empty())
    throw std::invalid_argument(
        "record " + std::to_string(record) + ": the " + what + " unit '" + label +
        "' is not one robodamp knows (m, mm, um, in, m/s, mm/s, in/s, m/s^2, g, N, kN, lbf, V, mV)");
  if (by_type) return {*by_type, 1.0};
  if (fallback) return {*fallback, 1.0};
  throw std::invalid_argument("record " + std::to_string(record) + ": the " + what +
                              " has neither a unit nor a data type (8, 11, 12) saying what it is");
}

const char* direction_name(int d) {
  static const char* const kNames[] = {"-RZ", "-RY", "-RX", "-Z",  "-Y",  "-X", "S",
                                       "+X",  "+Y",  "+Z",  "+RX", "+RY", "+RZ"};
  return d >= -6 && d <= 6 ? kNames[d + 6] : "?";
}

bool matches(const UffFunction& f, const std::optional<Dof>& response, const std::optional<Dof>& reference) {
  auto same = [](const std::optional<Dof>& want, int node, int dir) {
    return !want || (want->node == node && (want->direction == 0 || want->direction == dir));
  };
  return same(response, f.response_node, f.response_direction) &&
         same(reference, f.reference_node, f.reference_direction);
}

}  // namespace

Dof parse_dof(const std::string& text) {
  const std::size_t colon = text.find(':');
  Dof d;
  try {
    std::size_t used = 0;
    d.node = std::stoi(text.substr(0, colon), &used);
    if (used != text.substr(0, colon).size()) throw std::invalid_argument("node");
    if (colon != std::string::npos) {
      std::string dir = text.substr(colon + 1);
      int sign = 1;
      if (!dir.empty() && (dir[0] == '+' || dir[0] == '-')) sign = dir[0] == '-' ? -1 : 1, dir.erase(0, 1);
      if (dir == "x" || dir == "X")
        d.direction = sign * 1;
      else if (dir == "y" || dir == "Y")
        d.direction = sign * 2;
      else if (dir == "z" || dir == "Z")
        d.direction = sign * 3;
      else if (dir.size() == 1 && dir[0] >= '0' && dir[0] <= '6')
        d.direction = sign * (dir[0] - '0');
      else
        throw std::invalid_argument("direction");
    }
  } catch (const std::exception&) {
    throw std::invalid_argument(
        "'" + text + "' is not a DOF: NODE:DIR with DIR one of X, Y, Z, -X, -Y, -Z (or 1..6 with a sign), e.g. 12:+Y");
  }
  return d;
}

std::string dof_text(int node, int direction) { return std::to_string(node) + ":" + direction_name(direction); }

FrfUnits frf_units(const UffFunction& f, int record) {
  std::string num = f.ordinate.units, den = f.denominator.units;
  // An FRF unit written whole on the ordinate ("g/N", "(m/s^2)/N") with no denominator unit.
  if (known(den).empty() && !measfiles::unit_scale(num)) {
    const std::size_t slash = num.rfind('/');
    if (slash != std::string::npos && measfiles::unit_scale(num.substr(slash + 1))) {
      den = num.substr(slash + 1), num = num.substr(0, slash);
      if (num.size() >= 2 && num.front() == '(' && num.back() == ')') num = num.substr(1, num.size() - 2);
    }
  }
  const measfiles::UnitScale n = axis_scale(num, f.ordinate.data_type, std::nullopt, record, "ordinate");
  const measfiles::UnitScale d = axis_scale(den, f.denominator.data_type, Quantity::kForce, record, "denominator");
  FrfUnits u;
  if (d.quantity != Quantity::kForce && d.quantity != Quantity::kVoltage)
    throw std::invalid_argument("record " + std::to_string(record) + ": the denominator is in " +
                                measfiles::si_unit(d.quantity) + ": an FRF per force (N) or per voltage (V) is read");
  u.per_volt = d.quantity == Quantity::kVoltage;
  if (u.per_volt && n.quantity == Quantity::kForce) {
    u.force_per_volt = true, u.to_si = n.to_si / d.to_si;
    u.shown = "force per volt " + (known(num).empty() ? std::string("(SI)") : num) + "/" +
              (known(den).empty() ? "(SI)" : den) + " read as N/V";
    return u;
  }
  if (n.quantity == Quantity::kLength)
    u.kind = FrfKind::kReceptance;
  else if (n.quantity == Quantity::kVelocity)
    u.kind = FrfKind::kMobility;
  else if (n.quantity == Quantity::kAcceleration)
    u.kind = FrfKind::kAccelerance;
  else
    throw std::invalid_argument("record " + std::to_string(record) + ": the ordinate is in " +
                                measfiles::si_unit(n.quantity) + ": displacement, velocity or acceleration is read");
  u.to_si = n.to_si / d.to_si;
  const char* kind = u.kind == FrfKind::kReceptance ? "receptance"
                     : u.kind == FrfKind::kMobility ? "mobility"
                                                    : "accelerance";
  u.shown = std::string(kind) + " " + (known(num).empty() ? "(SI)" : num) + "/" + (known(den).empty() ? "(SI)" : den) +
            " read as " + measfiles::si_unit(n.quantity) + "/" + measfiles::si_unit(d.quantity);
  return u;
}

std::string describe_functions(const measfiles::UffFile& file) {
  std::string s;
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const UffFunction& f = file.functions[i];
    const char* type = f.function_type == measfiles::kUffFrf            ? "FRF"
                       : f.function_type == measfiles::kUffCoherence    ? "coherence"
                       : f.function_type == measfiles::kUffTimeResponse ? "time history"
                                                                        : "function";
    char line[256];
    std::snprintf(line, sizeof line, "  record %zu: %s %s / %s, %zu points %.6g .. %.6g, %s '%s'\n", i + 1, type,
                  dof_text(f.response_node, f.response_direction).c_str(),
                  dof_text(f.reference_node, f.reference_direction).c_str(), f.x.size(), f.x.front(), f.x.back(),
                  f.ordinate.units.c_str(), f.id[0].substr(0, 40).c_str());
    s += line;
  }
  return s;
}

UffFrf frf_from_uff(const measfiles::UffFile& file, const std::string& name, const UffSelection& s) {
  const std::string listing = "; the file holds:\n" + describe_functions(file);
  std::size_t at = file.functions.size();
  if (s.record) {
    if (*s.record < 1 || *s.record > static_cast<int>(file.functions.size()))
      throw std::invalid_argument(name + ": --record " + std::to_string(*s.record) + ": allowed 1 .. " +
                                  std::to_string(file.functions.size()) + listing);
    at = static_cast<std::size_t>(*s.record - 1);
  } else {
    int found = 0;
    for (std::size_t i = 0; i < file.functions.size(); ++i)
      if (file.functions[i].function_type == measfiles::kUffFrf && matches(file.functions[i], s.response, s.reference))
        ++found, at = i;
    if (found != 1)
      throw std::invalid_argument(name + ": " + std::to_string(found) + " FRF records match" +
                                  (s.response || s.reference ? " the --response and --reference given" : "") +
                                  "; choose one with --record N or --response NODE:DIR --reference NODE:DIR" + listing);
  }
  const UffFunction& f = file.functions[at];
  const int record = static_cast<int>(at + 1);
  if (f.function_type != measfiles::kUffFrf)
    throw std::invalid_argument(name + ": record " + std::to_string(record) + " is not an FRF (function type " +
                                std::to_string(f.function_type) + ", 4 is an FRF)" + listing);
  if (f.abscissa.data_type == measfiles::kUffTime)
    throw std::invalid_argument(name + ": record " + std::to_string(record) + " runs over time, not frequency");
  double x_scale = 1.0;
  if (const auto u = measfiles::unit_scale(f.abscissa.units)) {
    if (u->quantity != Quantity::kFrequency)
      throw std::invalid_argument(name + ": record " + std::to_string(record) + ": the abscissa is in '" +
                                  f.abscissa.units + "', not a frequency");
    x_scale = u->to_si;
  }
  UffFrf out;
  out.record = record, out.function = &f;
  try {
    out.units = frf_units(f, record);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name + ": " + e.what());
  }
  const UffFunction* coherence = nullptr;
  for (const auto& c : file.functions)
    if (c.function_type == measfiles::kUffCoherence && c.response_node == f.response_node &&
        c.reference_node == f.reference_node && c.response_direction == f.response_direction &&
        c.reference_direction == f.reference_direction && c.x.size() == f.x.size())
      coherence = &c;
  for (std::size_t k = 0; k < f.x.size(); ++k) {
    const double hz = f.x[k] * x_scale;
    const std::complex<double> iw(0.0, kTwoPi * hz);
    std::complex<double> h = f.y[k] * out.units.to_si;
    if (s.to_receptance && !out.units.force_per_volt) {
      if (out.units.kind != FrfKind::kReceptance && !(hz > 0.0)) continue;  // no receptance at 0 Hz from a rate
      if (out.units.kind == FrfKind::kMobility) h /= iw;
      if (out.units.kind == FrfKind::kAccelerance) h /= iw * iw;
    }
    out.data.f_hz.push_back(hz), out.data.h.push_back(h);
    if (coherence != nullptr) out.data.coherence.push_back(coherence->y[k].real());
  }
  return out;
}

UffSeries time_series_from_uff(const measfiles::UffFile& file, const std::string& name, const UffSelection& s) {
  const std::string listing = "; the file holds:\n" + describe_functions(file);
  UffSeries out;
  const UffFunction* force = nullptr;
  const UffFunction* response = nullptr;
  double force_si = 1.0, response_si = 1.0;
  int forces = 0, responses = 0;
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const UffFunction& f = file.functions[i];
    if (f.function_type != measfiles::kUffTimeResponse || f.is_complex) continue;
    const auto by_type = quantity_of_type(f.ordinate.data_type);
    const auto unit = measfiles::unit_scale(f.ordinate.units);
    const std::optional<Quantity> q = unit ? std::optional<Quantity>(unit->quantity) : by_type;
    const double si = unit ? unit->to_si : 1.0;
    if (q == Quantity::kForce) {
      ++forces, force = &f, force_si = si, out.force_record = static_cast<int>(i + 1);
    } else if ((q == Quantity::kLength || q == Quantity::kVelocity || q == Quantity::kAcceleration) &&
               matches(f, s.response, std::nullopt) && (!s.record || *s.record == static_cast<int>(i + 1))) {
      ++responses, response = &f, response_si = si, out.response_record = static_cast<int>(i + 1);
      out.kind = q == Quantity::kLength     ? FrfKind::kReceptance
                 : q == Quantity::kVelocity ? FrfKind::kMobility
                                            : FrfKind::kAccelerance;
    }
  }
  if (forces != 1)
    throw std::invalid_argument(name + ": " + std::to_string(forces) +
                                " time histories of a force (the hammer's): one is needed" + listing);
  if (responses != 1)
    throw std::invalid_argument(
        name + ": " + std::to_string(responses) +
        " time histories of a response match; choose one with --response NODE:DIR or --record N" + listing);
  if (force->x.size() != response->x.size() || force->x.size() < 64)
    throw std::invalid_argument(name + ": records " + std::to_string(out.force_record) + " and " +
                                std::to_string(out.response_record) + " hold " + std::to_string(force->x.size()) +
                                " and " + std::to_string(response->x.size()) +
                                " samples: the same number, at least 64, is needed");
  const double dt = (force->x.back() - force->x.front()) / static_cast<double>(force->x.size() - 1);
  for (std::size_t k = 0; k < force->x.size(); ++k)
    if (std::abs(force->x[k] - response->x[k]) > 1e-6 * dt ||
        (k > 0 && std::abs(force->x[k] - force->x[k - 1] - dt) > 1e-3 * dt))
      throw std::invalid_argument(
          name + ": records " + std::to_string(out.force_record) + " and " + std::to_string(out.response_record) +
          " are not sampled together at a constant rate (sample " + std::to_string(k + 1) + ")");
  if (!(dt > 0.0)) throw std::invalid_argument(name + ": the time does not increase");
  double t_scale = 1.0;
  if (const auto u = measfiles::unit_scale(force->abscissa.units); u && u->quantity == Quantity::kTime)
    t_scale = u->to_si;
  out.series.fs_hz = 1.0 / (dt * t_scale);
  for (std::size_t k = 0; k < force->x.size(); ++k)
    out.series.input.push_back(force->y[k].real() * force_si),
        out.series.output.push_back(response->y[k].real() * response_si);
  return out;
}

bool looks_like_uff(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t a = line.find_first_not_of(" \t\r");
    if (a == std::string::npos) continue;
    return line.compare(a, 2, "-1") == 0 && line.find_first_not_of(" \t\r", a + 2) == std::string::npos;
  }
  return false;
}

}  // namespace robodamp::identify
