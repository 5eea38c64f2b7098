#include "identify/commissioning.hpp"

#include "identify/common_pole_fit.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "analysis/loop_model.hpp"
#include "config/file_paths.hpp"
#include "identify/actuator_discrete.hpp"
#include "rt/recording.hpp"
#include "sim_plant/sensor.hpp"
#include "units/units.hpp"

namespace robodamp::identify {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string frf_name(const config::Config& cfg, int g, int h) {
  for (const auto& f : cfg.robot.frfs)
    if (f.response_location == g && f.excitation_location == h) return f.name;
  std::string name = "H";
  name += std::to_string(g);
  name += std::to_string(h);
  return name;
}

// The robot's FRFs from the directory: one per pair of locations (the lower triangle; the upper follows
// by reciprocity).
std::vector<IdentifiedFrf> read_frfs(const std::string& dir, const MeasurementManifest& m, const config::Config& cfg) {
  std::vector<IdentifiedFrf> out;
  for (std::size_t h = 0; h < m.locations.size(); ++h) {
    for (std::size_t g = h; g < m.locations.size(); ++g) {
      IdentifiedFrf f;
      f.response_id = m.locations[g].first, f.excitation_id = m.locations[h].first;
      f.name = frf_name(cfg, f.response_id, f.excitation_id);
      f.file = analysis::frf_file_name(f.response_id, f.excitation_id);
      const std::string path = (fs::path(dir) / f.file).string();
      if (!fs::exists(path))
        throw std::invalid_argument(path +
                                    " is missing: the plant side of robodamp measure writes it (the simulated "
                                    "plant in process, or robodamp plant --measure-out " +
                                    dir + " with hardware)");
      f.data = read_frf_csv(path, FrfKind::kReceptance);
      out.push_back(std::move(f));
    }
  }
  return out;
}

// Each FRF's modes.
void fit_frfs(std::vector<IdentifiedFrf>& out, const config::Config& cfg, const CommissioningSettings& s,
              std::string& pole_fit) {
  ModalFitSettings ms;
  ms.band_lo_hz = cfg.analysis.band_min_hz, ms.band_hi_hz = cfg.analysis.band_max_hz;
  ms.max_order = s.max_order, ms.min_coherence = s.min_coherence;
  // The poles common to all of them (a close pair one FRF shows as one peak is apart in another), each
  // FRF's residues its own; one by one when the band is too wide for one common fit.
  std::vector<FrfData> data;
  for (const auto& f : out) data.push_back(f.data);
  try {
    const std::vector<ModalFit> fits = fit_modes_common(data, ms);
    for (std::size_t i = 0; i < out.size(); ++i) out[i].fit = fits[i];
    pole_fit = "common poles over " + std::to_string(out.size()) + " FRFs";
    return;
  } catch (const std::invalid_argument&) {
    pole_fit = "poles per FRF";
  }
  for (auto& f : out) {
    try {
      f.fit = fit_modes(f.data, ms);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(f.file + " (" + f.name + "): " + e.what());
    }
  }
}

double mode_peak(const IdentifiedMode& m) {
  return std::hypot(m.residue_re, m.residue_im) / (m.damping_ratio * kTwoPi * m.natural_freq_hz);
}

// A number as the configuration writes it (7 significant digits, enough for every identified value).
YAML::Node num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.7g", v);
  return YAML::Node(std::string(b));
}

YAML::Node modes_node(const ModalFit& fit) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (const auto& m : fit.modes) {
    YAML::Node n;
    n["natural_freq_hz"] = num(m.natural_freq_hz);
    n["damping_ratio"] = num(m.damping_ratio);
    n["residue_re_m_per_n"] = num(m.residue_re);
    n["residue_im_m_per_n"] = num(m.residue_im);
    n.SetStyle(YAML::EmitterStyle::Flow);
    list.push_back(n);
  }
  return list;
}

// The measured configuration with what was identified in place of what was typed in.
std::string compose_yaml(const CommissioningResult& r, int polarity) {
  YAML::Node root = YAML::Load(r.manifest.config_text);
  YAML::Node act = root["actuator"];
  act["constant_n_per_v"] = num(r.actuator.force_constant_n_per_v);
  act["natural_freq_hz"] = num(r.actuator.natural_freq_hz);
  act["damping_ratio"] = num(r.actuator.damping_ratio);
  act["delay_s"] = num(r.actuator.delay_ms * 1e-3);
  YAML::Node robot(YAML::NodeType::Map);
  YAML::Node locs(YAML::NodeType::Sequence);
  for (const auto& [id, name] : r.manifest.locations) {
    YAML::Node l;
    l["id"] = id, l["name"] = name, l["axis_sign"] = 1;  // measured in the physical frame
    l.SetStyle(YAML::EmitterStyle::Flow);
    locs.push_back(l);
  }
  robot["locations"] = locs;
  YAML::Node frfs(YAML::NodeType::Sequence);
  for (const auto& f : r.frfs) {
    YAML::Node n;
    n["name"] = f.name;
    n["response_location"] = f.response_id;
    n["excitation_location"] = f.excitation_id;
    n["modes"] = modes_node(f.fit);
    frfs.push_back(n);
  }
  robot["frfs"] = frfs;
  root["robot"] = robot;
  root["controller"]["polarity"] = polarity;
  root["controller"]["match_freq_hz"] = num(r.dominant_mode_hz);
  // Files the measured configuration names relative to itself (the robot model, the job, the parameter
  // sets, ...) stay reachable from wherever the identified configuration is written.
  const fs::path base = fs::path(r.manifest.config_source).parent_path();
  for (const auto& key : config::file_path_keys()) {
    YAML::Node v = config::yaml_at(root, key);
    if (!v.IsDefined() || !v.IsScalar() || v.Scalar().empty()) continue;
    if (const fs::path p = v.Scalar(); p.is_relative()) v = (base / p).lexically_normal().string();
  }
  YAML::Emitter out;
  out.SetIndent(2);
  out << root;
  std::ostringstream os;
  os << "# robodamp identify all: the configuration " << r.manifest.config_source
     << " with the robot's FRFs, the actuator and the\n# compensator's match frequency identified from a robodamp "
        "measure "
        "run (docs/identification.md).\n"
     << out.c_str() << '\n';
  return os.str();
}

void analyse_into(CommissioningResult& r) {
  const analysis::LoopModel model(r.config);
  const analysis::AnalysisResult a = analysis::analyse(model);
  r.stable = a.stable;
  r.max_stable_gain_ns_per_m = a.max_stable_gain_ns_per_m;
  r.gain_ns_per_m = a.gain_ns_per_m;
  r.gain_margin_db = a.margins.gain_margin_db;
  r.phase_margin_deg = a.margins.phase_margin_deg;
  r.polarity_reason = a.polarity_reason;
  r.improvements_pct.clear();
  for (const auto& f : a.frfs_discrete) r.improvements_pct.emplace_back(f.name, f.improvement_pct);
}

}  // namespace

const IdentifiedFrf& path_between(const std::vector<IdentifiedFrf>& frfs, int a, int b) {
  for (const auto& f : frfs)
    if ((f.response_id == a && f.excitation_id == b) || (f.response_id == b && f.excitation_id == a)) return f;
  throw std::invalid_argument("no FRF between locations " + std::to_string(a) + " and " + std::to_string(b) +
                              " was measured");
}

namespace {

// Where a recording's chirp starts (s): its start time, or the tick after the chosen start command.
double chirp_start_s(const rt::Recording& rec, const rt::PeriodicChirp& sig, double fs_hz,
                     std::optional<double> wanted_s, const std::string& path) {
  if (!sig.on_command) return sig.start_s;
  std::vector<double> starts;
  for (const auto& f : rec.frames)
    if (static_cast<rt::CommandKind>(f.command_kind) == rt::CommandKind::kStartExcitation)
      starts.push_back(static_cast<double>(f.tick + 1) / fs_hz);
  if (starts.empty())
    throw std::invalid_argument(path + ": its chirp waits for a command and none came (no dwell measured)");
  if (!wanted_s) return starts.front();
  for (const double t : starts)
    if (std::abs(t - *wanted_s) <= 0.5 / fs_hz) return t;
  throw std::invalid_argument(path + ": no chirp starts at " + std::to_string(*wanted_s) +
                              " s (the measurement.json's "
                              "plan.chirp_start_s); its chirps start at " +
                              std::to_string(starts.size()) + " other times");
}

}  // namespace

ChirpMeasurement read_chirp_measurement(const std::string& path, const std::string& config_source,
                                        std::optional<double> start_s) {
  if (!fs::exists(path)) throw std::invalid_argument(path + " is missing: robodamp measure records the loop there");
  const rt::Recording rec = rt::read_recording(path);
  ChirpMeasurement m;
  m.fs_hz = rec.header.at("rate_hz");
  const rt::PeriodicChirp sig = rt::excitation_from(rec.header);
  if (!sig.enabled)
    throw std::invalid_argument(path + " holds no test signal (a robodamp run recording, not a robodamp measure one)");
  if (rec.frames.empty()) throw std::invalid_argument(path + " holds no frames");
  m.config = config::parse_config(rec.header.at("config_yaml").get<std::string>(),
                                  config_source.empty() ? rec.header.value("config_source", path) : config_source);
  // Samples by tick; a skipped tick holds the command and repeats the sample, as the devices do.
  const std::uint64_t n = rec.frames.back().tick + 1;
  std::vector<double> u(n, 0.0), y(n, 0.0);
  std::uint64_t next = 0;
  for (const auto& f : rec.frames) {
    for (; next < f.tick; ++next) u[next] = next > 0 ? u[next - 1] : 0.0, y[next] = next > 0 ? y[next - 1] : 0.0;
    u[f.tick] = f.command_v, y[f.tick] = f.accel_mps2;
    next = f.tick + 1;
  }
  const auto period_n = static_cast<std::size_t>(std::lround(sig.period_s * m.fs_hz));
  const auto first =
      static_cast<std::size_t>(std::lround(chirp_start_s(rec, sig, m.fs_hz, start_s, path) * m.fs_hz)) + period_n;
  m.periods_averaged = sig.periods - 1;  // the first period is the transient
  m.f0_hz = sig.f0_hz, m.f1_hz = sig.f1_hz;
  m.accel_per_volt = periodic_frf(u, y, first, period_n, m.periods_averaged, m.fs_hz, sig.f1_hz);
  return m;
}

ActuatorFit identify_actuator(const ChirpMeasurement& m, const config::Config& structure, double band_lo_hz,
                              double band_hi_hz, double min_coherence) {
  const sim::PlantModel plant = sim::build_plant_model(structure);
  const std::size_t sensor_index = plant.index_of(structure.sensor.location), actuator_index = plant.actuator.location;
  const sim::Accelerometer sensor(m.config.sensor, m.fs_hz, 1);
  const ActuatorFrf g = force_per_volt_from_acceleration(
      m.accel_per_volt, [&](double f) { return plant.receptance(sensor_index, actuator_index, f); },
      [&](double f) { return sensor.response(f); }, 1.0 / m.fs_hz);
  ActuatorFitSettings as;
  const bool given = band_hi_hz > band_lo_hz;
  as.band_lo_hz = std::max(m.f0_hz, given ? band_lo_hz : m.config.analysis.band_min_hz);
  as.band_hi_hz = std::min(m.f1_hz, given ? band_hi_hz : m.config.analysis.band_max_hz);
  as.min_coherence = min_coherence;
  return refine_actuator_discrete(fit_actuator(g, as), m.accel_per_volt, structure);
}

config::Config with_collocated_structure(const config::Config& base, const ModalFit& fit) {
  if (base.sensor.location != base.actuator.location)
    throw std::invalid_argument("the sensor (location " + std::to_string(base.sensor.location) +
                                ") and the actuator (location " + std::to_string(base.actuator.location) +
                                ") are not collocated: one FRF does not describe the structure; use identify all");
  config::Config c = base;
  c.robot.locations = {{base.sensor.location, "sensor and actuator", 1}};
  config::FrfConfig frf;
  frf.name = "structure";
  frf.response_location = frf.excitation_location = base.sensor.location;
  for (const auto& m : fit.modes) {
    config::ModeConfig mc;
    mc.natural_freq_hz = m.natural_freq_hz, mc.damping_ratio = m.damping_ratio;
    mc.residue_re_m_per_n = m.residue_re, mc.residue_im_m_per_n = m.residue_im;
    frf.modes.push_back(mc);
  }
  c.robot.frfs = {frf};
  c.disturbances.drives_on = false;
  c.disturbances.drive_vibration_location = base.sensor.location;
  c.controller.match_freq_hz = fit.modes.empty() ? 10.0 : fit.modes.front().natural_freq_hz;
  return c;
}

json to_json(const MeasurementManifest& m) {
  json locs = json::array();
  for (const auto& [id, name] : m.locations) locs.push_back({{"id", id}, {"name", name}});
  return {{"format", "robodamp-measurement"},
          {"format_version", 1},
          {"config_source", m.config_source},
          {"config_yaml", m.config_text},
          {"backend", m.backend},
          {"loop_rate_hz", m.loop_rate_hz},
          {"recording", kRecordingName},
          {"plan",
           {{"chirp_start_s", m.plan.chirp_start_s},
            {"chirp_end_s", m.plan.chirp_end_s},
            {"chirp_amplitude_v", m.plan.chirp_amplitude_v},
            {"predicted_peak_force_n", m.plan.predicted_peak_force_n},
            {"impacts_start_s", m.plan.impacts_start_s},
            {"duration_s", m.plan.duration_s}}},
          {"locations", locs},
          {"sensor_location_id", m.sensor_location_id},
          {"actuator_location_id", m.actuator_location_id},
          {"pose", m.pose_deg.empty()
                       ? json(nullptr)
                       : json{{"name", m.pose_name}, {"joints_deg", m.pose_deg}, {"robot_model", m.robot_model}}},
          {"run", m.run}};
}

MeasurementManifest read_manifest(const std::string& dir) {
  const std::string path = (fs::path(dir) / kManifestName).string();
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + " cannot be read: run robodamp measure --out " + dir + " first");
  json j;
  try {
    j = json::parse(in);
    MeasurementManifest m;
    if (j.at("format") != "robodamp-measurement") throw std::invalid_argument("format is not robodamp-measurement");
    m.config_source = j.at("config_source");
    m.config_text = j.at("config_yaml");
    m.backend = j.at("backend");
    m.loop_rate_hz = j.at("loop_rate_hz");
    const json& p = j.at("plan");
    m.plan.chirp_start_s = p.at("chirp_start_s");
    m.plan.chirp_end_s = p.at("chirp_end_s");
    m.plan.chirp_amplitude_v = p.at("chirp_amplitude_v");
    m.plan.predicted_peak_force_n = p.at("predicted_peak_force_n");
    m.plan.impacts_start_s = p.at("impacts_start_s").get<std::vector<double>>();
    m.plan.duration_s = p.at("duration_s");
    for (const auto& l : j.at("locations"))
      m.locations.emplace_back(l.at("id").get<int>(), l.at("name").get<std::string>());
    m.sensor_location_id = j.at("sensor_location_id");
    m.actuator_location_id = j.at("actuator_location_id");
    m.run = j.value("run", json::object());
    if (j.contains("pose") && !j.at("pose").is_null()) {  // absent before robodamp measure --pose
      const json& q = j.at("pose");
      m.pose_deg = q.at("joints_deg").get<std::vector<double>>();
      m.pose_name = q.value("name", "");
      m.robot_model = q.value("robot_model", "");
    }
    return m;
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

CommissioningInputs read_measurement_dir(const std::string& dir) {
  CommissioningInputs in;
  in.manifest = read_manifest(dir);
  const config::Config measured = config::parse_config(in.manifest.config_text, in.manifest.config_source);
  in.frfs = read_frfs(dir, in.manifest, measured);
  in.chirp = read_chirp_measurement((fs::path(dir) / kRecordingName).string(), in.manifest.config_source,
                                    in.manifest.plan.chirp_start_s);
  in.identified_path = (fs::path(dir) / "identified.yaml").string();
  return in;
}

CommissioningResult identify_all(const std::string& dir, const CommissioningSettings& s) {
  return identify_all(read_measurement_dir(dir), s);
}

CommissioningResult identify_all(const CommissioningInputs& in, const CommissioningSettings& s) {
  CommissioningResult r;
  r.manifest = in.manifest;
  const config::Config measured = config::parse_config(r.manifest.config_text, r.manifest.config_source);
  r.frfs = in.frfs;
  fit_frfs(r.frfs, measured, s, r.pole_fit);

  // The structure between the actuator and the sensor: the dominant mode, and the path the chirp
  // went through.
  const IdentifiedFrf& path = path_between(r.frfs, r.manifest.sensor_location_id, r.manifest.actuator_location_id);
  double best = -1.0;
  for (const auto& m : path.fit.modes)
    if (mode_peak(m) > best) best = mode_peak(m), r.dominant_mode_hz = m.natural_freq_hz;

  // The actuator against the identified structure (the measured configuration's actuator meanwhile).
  const ChirpMeasurement& chirp = in.chirp;
  r.actuator_periods = chirp.periods_averaged;
  r.actuator.force_constant_n_per_v = measured.actuator.constant_n_per_v;
  r.actuator.natural_freq_hz = measured.actuator.natural_freq_hz;
  r.actuator.damping_ratio = measured.actuator.damping_ratio;
  r.actuator.delay_ms = measured.actuator.delay_s * 1e3;
  r.polarity = measured.controller.polarity;
  const config::Config structure = config::parse_config(compose_yaml(r, r.polarity), "the identified structure");
  if (in.force_per_volt) {
    ActuatorFitSettings as;
    as.band_lo_hz = measured.analysis.band_min_hz, as.band_hi_hz = measured.analysis.band_max_hz;
    as.min_coherence = s.actuator_min_coherence;
    r.actuator = fit_actuator(*in.force_per_volt, as);
  } else {
    r.actuator = identify_actuator(chirp, structure, 0.0, 0.0, s.actuator_min_coherence);
  }

  // The configuration: first with the measured polarity, then with the one the analysis recommends.
  for (int pass = 0; pass < 2; ++pass) {
    r.yaml = compose_yaml(r, r.polarity);
    r.config = config::parse_config(r.yaml, in.identified_path);
    const analysis::LoopModel model(r.config);
    const int recommended = analysis::analyse(model).recommended_polarity;
    if (recommended == r.polarity) break;
    r.polarity = recommended;
  }
  analyse_into(r);
  return r;
}

json to_json(const CommissioningResult& r) {
  json frfs = json::array();
  for (const auto& f : r.frfs) {
    json modes = json::array();
    for (const auto& m : f.fit.modes)
      modes.push_back({{"natural_freq_hz", m.natural_freq_hz},
                       {"damping_ratio", m.damping_ratio},
                       {"residue_re_m_per_n", m.residue_re},
                       {"residue_im_m_per_n", m.residue_im},
                       {"stiffness_n_per_m", m.stiffness_n_per_m}});
    frfs.push_back({{"name", f.name},
                    {"response_location", f.response_id},
                    {"excitation_location", f.excitation_id},
                    {"file", f.file},
                    {"modes", modes},
                    {"fit_error_pct", f.fit.fit_error_pct},
                    {"band_hz", {f.fit.band_lo_hz, f.fit.band_hi_hz}}});
  }
  auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json imp = json::object();
  for (const auto& [name, pct] : r.improvements_pct) imp[name] = pct;
  return {{"frfs", frfs},
          {"pole_fit", r.pole_fit},
          {"actuator",
           {{"mounting", config::to_string(r.config.actuator.mounting)},
            {"force_constant_n_per_v", r.actuator.force_constant_n_per_v},
            {"natural_freq_hz", r.actuator.natural_freq_hz},
            {"damping_ratio", r.actuator.damping_ratio},
            {"delay_ms", r.actuator.delay_ms},
            {"fit_error_pct", r.actuator.fit_error_pct},
            {"band_hz", {r.actuator.band_lo_hz, r.actuator.band_hi_hz}},
            {"points", r.actuator.points},
            {"periods_averaged", r.actuator_periods}}},
          {"dominant_mode_hz", r.dominant_mode_hz},
          {"polarity", r.polarity},
          {"analysis",
           {{"stable", r.stable},
            {"gain_ns_per_m", r.gain_ns_per_m},
            {"max_stable_gain_ns_per_m", opt(r.max_stable_gain_ns_per_m)},
            {"gain_margin_db", opt(r.gain_margin_db)},
            {"phase_margin_deg", opt(r.phase_margin_deg)},
            {"improvement_pct", imp}}}};
}

std::string summary_text(const CommissioningResult& r) {
  std::ostringstream os;
  char b[256];
  os << "  modes: " << r.pole_fit << "\n";
  for (const auto& f : r.frfs) {
    std::snprintf(b, sizeof b, "  %s (%s): %zu modes, fit error %.2f %% over %.1f-%.1f Hz\n", f.name.c_str(),
                  f.file.c_str(), f.fit.modes.size(), f.fit.fit_error_pct, f.fit.band_lo_hz, f.fit.band_hi_hz);
    os << b;
    for (const auto& m : f.fit.modes) {
      std::snprintf(b, sizeof b, "    %7.3f Hz  zeta %.4f  residue %+.4g %+.4gi m/N\n", m.natural_freq_hz,
                    m.damping_ratio, m.residue_re, m.residue_im);
      os << b;
    }
  }
  const auto& a = r.actuator;
  std::snprintf(b, sizeof b,
                "  actuator (%s): T %.4g N/V, %.3f Hz, zeta %.4f, delay %.3f ms; fit error %.2f %% over %.1f-%.1f Hz "
                "(%d points, %d periods)\n",
                config::to_string(r.config.actuator.mounting), a.force_constant_n_per_v, a.natural_freq_hz,
                a.damping_ratio, a.delay_ms, a.fit_error_pct, a.band_lo_hz, a.band_hi_hz, a.points, r.actuator_periods);
  os << b;
  std::snprintf(b, sizeof b, "  compensator matched at %.3f Hz (dominant mode), polarity %+d\n", r.dominant_mode_hz,
                r.polarity);
  os << b;
  std::snprintf(b, sizeof b, "  analysis: %s at K = %.0f N s/m; K_max %s N s/m", r.stable ? "stable" : "UNSTABLE",
                r.gain_ns_per_m,
                r.max_stable_gain_ns_per_m ? std::to_string(std::lround(*r.max_stable_gain_ns_per_m)).c_str() : "none");
  os << b;
  if (r.phase_margin_deg) os << ", phase margin " << std::lround(*r.phase_margin_deg) << " deg";
  os << '\n';
  for (const auto& [name, pct] : r.improvements_pct) {
    std::snprintf(b, sizeof b, "  improvement %s: %.1f %%\n", name.c_str(), pct);
    os << b;
  }
  return os.str();
}

}  // namespace robodamp::identify
