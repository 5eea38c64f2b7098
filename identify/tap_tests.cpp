#include "identify/tap_tests.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <stdexcept>

#include "identify/uff_frf.hpp"
#include "measfiles/uff.hpp"
#include "units/units.hpp"

namespace robodamp::identify {

namespace {

namespace fs = std::filesystem;
using Pair = std::pair<int, int>;  // response, excitation

// Appended, not "H" + ...: GCC 12 at -O3 warns a false -Wstringop-overflow on operator+(const char*, string&&)
// where this file is compiled with others (the unity build).
std::string pair_text(Pair p) {
  std::string text = "H";
  text += std::to_string(p.first);
  text += std::to_string(p.second);
  return text;
}

void add(std::map<Pair, IdentifiedFrf>& found, IdentifiedFrf f) {
  const Pair p{f.response_id, f.excitation_id};
  if (const auto it = found.find(p); it != found.end())
    throw std::invalid_argument("two tap tests from node " + std::to_string(p.second) + " to node " +
                                std::to_string(p.first) + ": " + it->second.file + " and " + f.file + "; keep one");
  found.emplace(p, std::move(f));
}

void read_uff(const std::string& path, const std::vector<int>& ids, std::map<Pair, IdentifiedFrf>& found) {
  const measfiles::UffFile file = measfiles::read_uff(path);
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const auto& fn = file.functions[i];
    if (fn.function_type != measfiles::kUffFrf) continue;
    const bool known = std::count(ids.begin(), ids.end(), fn.response_node) > 0 &&
                       std::count(ids.begin(), ids.end(), fn.reference_node) > 0;
    if (!known) continue;
    UffSelection s;
    s.record = static_cast<int>(i + 1);
    UffFrf u = frf_from_uff(file, path, s);
    if (u.units.per_volt || u.units.force_per_volt) continue;  // an actuator's record: the chirp measures that
    IdentifiedFrf f;
    f.response_id = fn.response_node, f.excitation_id = fn.reference_node;
    f.file = path + " record " + std::to_string(u.record);
    f.data = std::move(u.data);
    add(found, std::move(f));
  }
}

std::optional<Pair> csv_pair(const std::string& path) {
  static const std::regex name(R"(frf_(\d+)_(\d+)\.csv)", std::regex::icase);
  std::smatch m;
  const std::string base = fs::path(path).filename().string();
  if (!std::regex_match(base, m, name)) return std::nullopt;
  return Pair{std::stoi(m[1].str()), std::stoi(m[2].str())};
}

// RMS of |a - b| over RMS of |a| where both are coherent and f is in [lo, hi]; -1 when no point is.
double relative_rms_pct(const std::vector<double>& f_hz, const std::vector<Complex>& a, const std::vector<Complex>& b,
                        const std::vector<double>& coh, double lo, double hi, double min_coherence) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < f_hz.size(); ++i) {
    if (f_hz[i] < lo || f_hz[i] > hi || (!coh.empty() && coh[i] < min_coherence)) continue;
    num += std::norm(a[i] - b[i]);
    den += std::norm(a[i]);
  }
  return den > 0.0 ? 100.0 * std::sqrt(num / den) : -1.0;
}

// An FRF linearly interpolated onto other lines (coherence 0 outside its own range: left out).
std::pair<std::vector<Complex>, std::vector<double>> on_lines(const FrfData& d, const std::vector<double>& f_hz) {
  std::vector<Complex> h(f_hz.size());
  std::vector<double> coh(f_hz.size(), 0.0);
  std::size_t j = 0;
  for (std::size_t i = 0; i < f_hz.size(); ++i) {
    const double f = f_hz[i];
    while (j + 1 < d.f_hz.size() && d.f_hz[j + 1] < f) ++j;
    if (j + 1 >= d.f_hz.size() || f < d.f_hz[j]) continue;
    const double t = (f - d.f_hz[j]) / (d.f_hz[j + 1] - d.f_hz[j]);
    h[i] = d.h[j] + t * (d.h[j + 1] - d.h[j]);
    coh[i] = d.coherence.empty() ? 1.0 : std::min(d.coherence[j], d.coherence[j + 1]);
  }
  return {h, coh};
}

// The modes of the chirp's own FRF (acceleration per volt over -w^2: the actuator's dynamics times the
// structure's receptance, whose poles are the structure's and the actuator's).
std::vector<IdentifiedMode> chirp_modes(const ChirpMeasurement& c, double lo, double hi, std::string& how) {
  FrfData d;
  for (std::size_t i = 0; i < c.accel_per_volt.f_hz.size(); ++i) {
    const double f = c.accel_per_volt.f_hz[i];
    if (f <= 0.0) continue;
    const double w = kTwoPi * f;
    d.f_hz.push_back(f);
    d.h.push_back(c.accel_per_volt.h1[i] / (-w * w));
    d.coherence.push_back(c.accel_per_volt.coherence[i]);
  }
  ModalFitSettings s;
  s.band_lo_hz = lo, s.band_hi_hz = hi;
  s.max_order = 60;  // as identify all's: the actuator's pole sits among the structure's
  s.min_coherence = 0.9;
  try {
    const ModalFit fit = fit_modes(d, s);
    char b[320];
    std::snprintf(b, sizeof b,
                  "the chirp's FRF fitted on its own over %.1f-%.1f Hz for its poles: %zu (only the poles are "
                  "compared: the actuator's dynamics in it are not of the modal form, the residues fit it to %.0f %%)",
                  lo, hi, fit.modes.size(), fit.fit_error_pct);
    how = b;
    return fit.modes;
  } catch (const std::invalid_argument& e) {
    how = std::string("the chirp's FRF could not be fitted on its own: ") + e.what();
    return {};
  }
}

// The actuator's fit error seen in what the chirp measured, the acceleration: |G - G_fit| and |G| each
// weighted by the tapped path's accelerance w^2 |H| (the sensor's and the output path's response is flat
// in the band). Near a zero of the tapped path the force per volt is a division by almost nothing and its
// error says nothing; in the acceleration it weighs what it weighs. A line whose error is ten times both
// its neighbours' is left out and counted: a periodic disturbance on one line (a robot's drives at 3 Hz
// repeat with the chirp's period and pass its averaging), where a structure that is not the chirp's
// leaves a band of lines around each of its modes.
double actuator_residual_pct(const CommissioningResult& r, const ModalFit& path, int& lines_left_out) {
  const ActuatorFit& a = r.actuator;
  lines_left_out = 0;
  if (a.f_hz.empty()) return a.fit_error_pct;
  const std::size_t n = a.f_hz.size();
  std::vector<double> weight(n), err(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = kTwoPi * a.f_hz[i];
    weight[i] = std::norm(w * w * fitted_receptance(path, a.f_hz[i]));
    err[i] = weight[i] * std::norm(a.measured[i] - a.fitted[i]);
  }
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double left = i > 0 ? err[i - 1] : err[std::min(i + 1, n - 1)];
    const double right = i + 1 < n ? err[i + 1] : left;
    if (n > 2 && err[i] > 100.0 * std::max(left, right)) {  // 10x in amplitude, squared here
      ++lines_left_out;
      continue;
    }
    num += err[i];
    den += weight[i] * std::norm(a.measured[i]);
  }
  return den > 0.0 ? 100.0 * std::sqrt(num / den) : a.fit_error_pct;
}

}  // namespace

TapTests read_tap_tests(const std::vector<std::string>& files, const MeasurementManifest& m,
                        const config::Config& cfg) {
  if (files.empty()) throw std::invalid_argument("no tap-test file given");
  std::vector<int> ids;
  for (const auto& l : m.locations) ids.push_back(l.first);
  std::map<Pair, IdentifiedFrf> found;
  TapTests t;
  for (const auto& path : files) {
    if (!fs::is_regular_file(path)) throw std::invalid_argument(path + ": no such file");
    t.files.push_back(path);
    if (const auto p = csv_pair(path)) {
      IdentifiedFrf f;
      f.response_id = p->first, f.excitation_id = p->second;
      f.file = path;
      f.data = read_frf_csv(path, FrfKind::kReceptance);
      add(found, std::move(f));
    } else {
      read_uff(path, ids, found);  // throws naming the file when it is not a universal file
    }
  }
  for (std::size_t h = 0; h < ids.size(); ++h) {
    for (std::size_t g = h; g < ids.size(); ++g) {
      const Pair want{ids[g], ids[h]}, back{ids[h], ids[g]};
      auto it = found.find(want);
      const auto other = found.find(back);
      if (it == found.end()) it = other;
      if (it == found.end())
        throw std::invalid_argument("the tap tests hold no FRF between locations " + std::to_string(ids[g]) + " and " +
                                    std::to_string(ids[h]) +
                                    " (either way round; UFF nodes are the configuration's location "
                                    "ids, CSVs are named frf_<response>_<excitation>.csv) in " +
                                    std::to_string(files.size()) + " file(s)");
      IdentifiedFrf f = it->second;
      f.name = pair_text({f.response_id, f.excitation_id});
      for (const auto& c : cfg.robot.frfs)
        if (c.response_location == f.response_id && c.excitation_location == f.excitation_id) f.name = c.name;
      if (g != h && other != found.end() && other != it) t.reciprocal.emplace_back(f, other->second);
      t.frfs.push_back(std::move(f));
    }
  }
  return t;
}

CommissioningInputs inputs_with_tap_tests(const std::string& dir, const std::vector<std::string>& files,
                                          TapTests& taps) {
  CommissioningInputs in;
  in.manifest = read_manifest(dir);
  const config::Config measured = config::parse_config(in.manifest.config_text, in.manifest.config_source);
  taps = read_tap_tests(files, in.manifest, measured);
  in.frfs = taps.frfs;
  in.chirp = read_chirp_measurement((fs::path(dir) / kRecordingName).string(), in.manifest.config_source);
  in.identified_path = (fs::path(dir) / "identified.yaml").string();
  return in;
}

std::string TapTestConsistency::failure() const {
  char b[512];
  for (const auto& m : modes) {
    if (m.ok) continue;
    if (!m.chirp_hz)
      std::snprintf(b, sizeof b, "the tap tests' mode at %.2f Hz: the actuator's chirp shows no pole (%s)", m.tap_hz,
                    chirp_fit.c_str());
    else
      std::snprintf(b, sizeof b,
                    "the tap tests contradict the actuator's chirp: their mode at %.2f Hz is at %.2f Hz in the chirp "
                    "(%.1f %% apart, allowed %.1f %%): another pose, another tool, or another robot?",
                    m.tap_hz, *m.chirp_hz, m.difference_pct, tolerance_pct);
    return b;
  }
  if (chirp_residual_pct > residual_limit_pct) {
    std::snprintf(
        b, sizeof b,
        "the tap tests contradict the actuator's chirp: through the tapped structure the chirp implies an "
        "actuator Eq. 3 fits only to %.1f %% RMS (allowed %.0f %%): another structure, or a mode just outside "
        "analysis.band_min_hz-band_max_hz that the identified structure leaves out",
        chirp_residual_pct, residual_limit_pct);
    return b;
  }
  for (const auto& r : reciprocity)
    if (r.difference_pct > reciprocity_limit_pct) {
      std::snprintf(b, sizeof b, "the tap tests are not reciprocal: %s differ by %.1f %% RMS (allowed %.0f %%)",
                    r.pair.c_str(), r.difference_pct, reciprocity_limit_pct);
      return b;
    }
  return {};
}

std::string TapTestConsistency::summary() const {
  std::string s;
  char b[200];
  for (const auto& m : modes) {
    if (m.chirp_hz)
      std::snprintf(b, sizeof b, "%s%.3f Hz tapped, %.3f Hz in the chirp (%.2f %%)", s.empty() ? "" : "; ", m.tap_hz,
                    *m.chirp_hz, m.difference_pct);
    else
      std::snprintf(b, sizeof b, "%s%.3f Hz tapped, none in the chirp", s.empty() ? "" : "; ", m.tap_hz);
    s += b;
  }
  std::snprintf(b, sizeof b,
                "; through the tapped structure the chirp implies an actuator Eq. 3 fits to %.2f %% RMS (%d lone "
                "line(s) left out)",
                chirp_residual_pct, residual_lines_left_out);
  s += b;
  for (const auto& r : reciprocity)
    std::snprintf(b, sizeof b, "; %s reciprocal within %.1f %%", r.pair.c_str(), r.difference_pct), s += b;
  return s;
}

TapTestConsistency check_tap_tests(const CommissioningInputs& in, const CommissioningResult& r, const TapTests& taps,
                                   double tolerance_pct) {
  TapTestConsistency c;
  c.tolerance_pct = tolerance_pct;
  const config::Config& cfg = r.config;
  const double lo = std::max(cfg.analysis.band_min_hz, in.chirp.f0_hz),
               hi = std::min(cfg.analysis.band_max_hz, in.chirp.f1_hz);
  const std::vector<IdentifiedMode> poles = chirp_modes(in.chirp, lo, hi, c.chirp_fit);
  const ModalFit& path_fit = path_between(r.frfs, r.manifest.sensor_location_id, r.manifest.actuator_location_id).fit;
  for (const auto& m : path_fit.modes) {
    if (m.natural_freq_hz < lo || m.natural_freq_hz > hi) continue;
    TapModeCheck t;
    t.tap_hz = m.natural_freq_hz, t.tap_damping = m.damping_ratio;
    for (const auto& p : poles)
      if (!t.chirp_hz || std::abs(p.natural_freq_hz - t.tap_hz) < std::abs(*t.chirp_hz - t.tap_hz))
        t.chirp_hz = p.natural_freq_hz, t.chirp_damping = p.damping_ratio;
    if (t.chirp_hz) t.difference_pct = 100.0 * std::abs(*t.chirp_hz - t.tap_hz) / t.tap_hz;
    t.ok = t.chirp_hz && t.difference_pct <= tolerance_pct;
    c.modes.push_back(t);
  }
  // The chirp against the identified actuator on the tapped structure: the force per volt the chirp implies
  // through the tapped structure (the loop's sensor and output path taken out) against Eq. 3's fit of it,
  // weighed in the acceleration. A structure that is not the chirp's leaves its modes in that ratio, which
  // Eq. 3 cannot follow.
  c.chirp_residual_pct = actuator_residual_pct(r, path_fit, c.residual_lines_left_out);
  for (const auto& [x, y] : taps.reciprocal) {
    const auto [yh, ycoh] = on_lines(y.data, x.data.f_hz);  // the reverse on the first one's lines
    std::vector<double> coh(x.data.f_hz.size(), 1.0);
    for (std::size_t i = 0; i < coh.size(); ++i) {
      if (!x.data.coherence.empty()) coh[i] = std::min(coh[i], x.data.coherence[i]);
      coh[i] = std::min(coh[i], ycoh[i]);
    }
    c.reciprocity.push_back({x.name + " and " + pair_text({y.response_id, y.excitation_id}),
                             relative_rms_pct(x.data.f_hz, x.data.h, yh, coh, lo, hi, 0.8)});
  }
  return c;
}

}  // namespace robodamp::identify
