#include "identify/uff_commissioning.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "identify/tap_tests.hpp"
#include "identify/uff_frf.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::identify {

namespace fs = std::filesystem;
using measfiles::UffFunction;

namespace {

constexpr int kDirection = 2;  // +Y

std::string today() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char b[32];
  std::strftime(b, sizeof b, "%d-%b-%y %H:%M:%S", std::gmtime(&t));
  return b;
}

UffFunction function_record(const std::string& title, const std::string& source, int response, int reference,
                            const std::vector<double>& f_hz) {
  UffFunction f;
  f.id = {title.substr(0, 80), source.substr(source.size() > 80 ? source.size() - 80 : 0), today(), "robodamp", "NONE"};
  f.response_node = response, f.response_direction = kDirection;
  f.reference_node = reference, f.reference_direction = kDirection;
  f.abscissa = {measfiles::kUffFrequency, 0, 0, 0, "Frequency", "Hz"};
  f.x = f_hz;
  return f;
}

UffFunction coherence_of(const UffFunction& frf, const std::vector<double>& coherence) {
  UffFunction c = frf;
  c.function_type = measfiles::kUffCoherence, c.is_complex = false;
  c.id[0] = ("coherence of " + frf.id[0]).substr(0, 80);
  c.ordinate = {measfiles::kUffGeneral, 0, 0, 0, "Coherence", "NONE"};
  c.denominator = {};
  c.y.assign(coherence.begin(), coherence.end());
  return c;
}

// The FRF between two locations in either direction; nullptr when the file holds none.
const IdentifiedFrf* between(const std::vector<IdentifiedFrf>& frfs, int a, int b) {
  for (const auto& f : frfs)
    if ((f.response_id == a && f.excitation_id == b) || (f.response_id == b && f.excitation_id == a)) return &f;
  return nullptr;
}

}  // namespace

measfiles::UffFile measurement_to_uff(const CommissioningInputs& in) {
  measfiles::UffFile file;
  for (const auto& [id, name] : in.manifest.locations) file.nodes.push_back({id, {0.0, 0.0, 0.0}});
  for (const auto& frf : in.frfs) {
    UffFunction f = function_record(frf.name + " receptance (impacts)", in.manifest.config_source, frf.response_id,
                                    frf.excitation_id, frf.data.f_hz);
    f.ordinate = {measfiles::kUffDisplacement, 1, 0, 0, "Displacement", "m"};
    f.denominator = {measfiles::kUffExcitationForce, 0, 1, 0, "Force", "N"};
    f.y = frf.data.h;
    file.functions.push_back(f);
    if (!frf.data.coherence.empty()) file.functions.push_back(coherence_of(f, frf.data.coherence));
  }
  const ChirpMeasurement& c = in.chirp;
  UffFunction a =
      function_record("actuator: acceleration per volt (chirp)", in.manifest.config_source,
                      in.manifest.sensor_location_id, in.manifest.actuator_location_id, c.accel_per_volt.f_hz);
  a.reference_entity = kVoltageEntity;
  a.id[4] = "chirp " + std::to_string(c.f0_hz) + " .. " + std::to_string(c.f1_hz) + " Hz, periods averaged " +
            std::to_string(c.periods_averaged);
  a.ordinate = {measfiles::kUffAcceleration, 1, 0, 0, "Acceleration", "m/s^2"};
  a.denominator = {measfiles::kUffGeneral, 0, 0, 0, "Voltage", "V"};
  a.y = c.accel_per_volt.h1;
  file.functions.push_back(a);
  file.functions.push_back(coherence_of(a, c.accel_per_volt.coherence));
  return file;
}

measfiles::UffFile modes_to_uff(const CommissioningResult& r) {
  measfiles::UffFile file;
  const int ref = r.manifest.actuator_location_id;
  for (const auto& [id, name] : r.manifest.locations) file.nodes.push_back({id, {0.0, 0.0, 0.0}});
  const IdentifiedFrf* driving = between(r.frfs, ref, ref);
  if (driving == nullptr)
    throw std::invalid_argument("no driving-point FRF at the actuator's location " + std::to_string(ref));
  int number = 0;
  for (const auto& m : driving->fit.modes) {
    const double wn = 2.0 * M_PI * m.natural_freq_hz;
    measfiles::UffMode u;
    u.number = ++number;
    u.id = {"robodamp identify all: mode " + std::to_string(number), r.manifest.config_source.substr(0, 80),
            "residue shapes, reference node " + std::to_string(ref) + " +Y, modal A = 1", today(), "NONE"};
    u.eigenvalue = {-m.damping_ratio * wn, wn * std::sqrt(1.0 - m.damping_ratio * m.damping_ratio)};
    const std::complex<double> psi_ref = std::sqrt(std::complex<double>(m.residue_re, m.residue_im));
    for (const auto& [id, name] : r.manifest.locations) {
      std::complex<double> residue = 0.0;
      if (const IdentifiedFrf* f = between(r.frfs, id, ref)) {
        double best = 0.02 * m.natural_freq_hz;  // the same mode: within 2 % in frequency
        for (const auto& o : f->fit.modes)
          if (std::abs(o.natural_freq_hz - m.natural_freq_hz) < best)
            best = std::abs(o.natural_freq_hz - m.natural_freq_hz), residue = {o.residue_re, o.residue_im};
      }
      u.shape.push_back({id, {0.0, std::abs(psi_ref) > 0.0 ? residue / psi_ref : 0.0, 0.0}});
    }
    file.modes.push_back(u);
  }
  return file;
}

std::optional<UffFrf> uff_frf_between(const measfiles::UffFile& file, const std::string& path, int response,
                                      int reference, bool per_volt) {
  for (const auto& [g, h] : {std::pair{response, reference}, std::pair{reference, response}}) {
    int found = 0;
    std::optional<UffFrf> hit;
    for (std::size_t i = 0; i < file.functions.size(); ++i) {
      const auto& f = file.functions[i];
      if (f.function_type != measfiles::kUffFrf || f.response_node != g || f.reference_node != h) continue;
      UffSelection s;
      s.record = static_cast<int>(i + 1), s.to_receptance = !per_volt;
      UffFrf u = frf_from_uff(file, path, s);
      if (u.units.per_volt != per_volt || u.units.force_per_volt) continue;
      ++found, hit = std::move(u);
    }
    if (found > 1)
      throw std::invalid_argument(path + ": " + std::to_string(found) + " FRF records between nodes " +
                                  std::to_string(g) + " and " + std::to_string(h) +
                                  (per_volt ? " per volt" : " per force") + "; keep one");
    if (hit) return hit;
    if (per_volt) break;
  }
  return std::nullopt;
}

namespace {

// The actuator: the sensor's acceleration per volt (robodamp's chirp), or else its force per volt.
void read_actuator(const measfiles::UffFile& file, const std::string& path, const config::Config& cfg,
                   CommissioningInputs& in) {
  const MeasurementManifest& m = in.manifest;
  ChirpMeasurement& c = in.chirp;
  c.config = cfg;
  c.fs_hz = cfg.loop.rate_hz;
  c.f0_hz = cfg.commissioning.chirp_f0_hz, c.f1_hz = cfg.commissioning.chirp_f1_hz;
  if (const auto a = uff_frf_between(file, path, m.sensor_location_id, m.actuator_location_id, true)) {
    if (a->units.kind != FrfKind::kAccelerance)
      throw std::invalid_argument(path + ": record " + std::to_string(a->record) +
                                  ": the actuator's FRF must be an acceleration per volt");
    c.accel_per_volt.f_hz = a->data.f_hz, c.accel_per_volt.h1 = a->data.h;
    c.accel_per_volt.coherence =
        a->data.coherence.empty() ? std::vector<double>(a->data.f_hz.size(), 1.0) : a->data.coherence;
    const std::string& note = a->function->id[4];
    if (const std::size_t at = note.find("periods averaged "); at != std::string::npos)
      c.periods_averaged = std::atoi(note.c_str() + at + 17);
    return;
  }
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const auto& f = file.functions[i];
    if (f.function_type != measfiles::kUffFrf || f.reference_node != m.actuator_location_id) continue;
    UffSelection s;
    s.record = static_cast<int>(i + 1), s.to_receptance = false;
    const UffFrf u = frf_from_uff(file, path, s);
    if (!u.units.force_per_volt) continue;
    in.force_per_volt = ActuatorFrf{u.data.f_hz, u.data.h, u.data.coherence};
    return;
  }
  throw std::invalid_argument(
      path + ": the actuator needs an FRF per volt with reference node " + std::to_string(m.actuator_location_id) +
      " (the actuator): the acceleration at node " + std::to_string(m.sensor_location_id) +
      " (the sensor, what robodamp measures with its chirp) or the actuator's force; the file holds:\n" +
      describe_functions(file));
}

}  // namespace

CommissioningInputs read_measurement_uff(const std::string& uff_path, const std::string& config_path) {
  CommissioningInputs in;
  const config::Config cfg = config::load_config_file(config_path);
  MeasurementManifest& m = in.manifest;
  m.config_source = fs::absolute(config_path).lexically_normal().string();
  m.config_text = cfg.yaml_text;
  m.backend = "universal file " + uff_path;
  m.loop_rate_hz = cfg.loop.rate_hz;
  for (const auto& l : cfg.robot.locations) m.locations.emplace_back(l.id, l.name);
  const sim::PlantModel model = sim::build_plant_model(cfg);
  m.sensor_location_id = cfg.sensor.location;
  m.actuator_location_id = model.locations[model.actuator.location].id;
  const measfiles::UffFile file = measfiles::read_uff(uff_path);
  for (std::size_t h = 0; h < m.locations.size(); ++h) {
    for (std::size_t g = h; g < m.locations.size(); ++g) {
      IdentifiedFrf f;
      f.response_id = m.locations[g].first, f.excitation_id = m.locations[h].first;
      f.name = "H";
      f.name += std::to_string(f.response_id);
      f.name += std::to_string(f.excitation_id);
      for (const auto& c : cfg.robot.frfs)
        if (c.response_location == f.response_id && c.excitation_location == f.excitation_id) f.name = c.name;
      const auto u = uff_frf_between(file, uff_path, f.response_id, f.excitation_id, false);
      if (!u)
        throw std::invalid_argument(uff_path + ": no FRF per force between nodes " + std::to_string(f.response_id) +
                                    " and " + std::to_string(f.excitation_id) +
                                    " (the configuration's locations); the file holds:\n" + describe_functions(file));
      f.file = uff_path + " record " + std::to_string(u->record);
      f.data = u->data;
      in.frfs.push_back(std::move(f));
    }
  }
  read_actuator(file, uff_path, cfg, in);
  in.identified_path = (fs::absolute(uff_path).parent_path() / "identified.yaml").string();
  return in;
}

CommissioningResult identify_all_files(const AllFiles& f, const CommissioningSettings& s, std::ostream& out) {
  TapTests taps;
  const CommissioningInputs in = !f.uff_path.empty()    ? read_measurement_uff(f.uff_path, f.config_path)
                                 : !f.tap_tests.empty() ? inputs_with_tap_tests(f.in_dir, f.tap_tests, taps)
                                                        : read_measurement_dir(f.in_dir);
  CommissioningResult r = identify_all(in, s);
  if (!f.tap_tests.empty()) {
    const TapTestConsistency c = check_tap_tests(in, r, taps);
    out << "robodamp identify all: the tap tests against the actuator's chirp: " << c.summary() << '\n';
    if (const std::string failed = c.failure(); !failed.empty()) throw std::invalid_argument(failed);
  }
  if (!f.modes_uff.empty()) {
    measfiles::write_uff(f.modes_uff, modes_to_uff(r), measfiles::UffEncoding::kAscii);
    out << "wrote " << f.modes_uff << '\n';
  }
  return r;
}

}  // namespace robodamp::identify
