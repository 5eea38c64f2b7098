#include "rt/recording.hpp"

#include <bit>
#include <cstring>
#include <ctime>

#include "rt/settings_fields.hpp"
#include "rt/version.hpp"

namespace robodamp::rt {

using nlohmann::json;

namespace {

json notch_json(const control::ControllerParams& p) {
  const auto& n = p.harmonic_notch;
  json refused = json::array();
  for (std::size_t i = 0; i < p.refused_rpm_count; ++i)
    refused.push_back({p.refused_rpm[i].first, p.refused_rpm[i].second});
  return {{"enabled", n.enabled},
          {"harmonics", n.harmonics},
          {"bandwidth_hz", n.bandwidth_hz},
          {"depth_db", n.depth_db},
          {"slew_fraction", n.slew_fraction},
          {"min_hz", n.min_hz},
          {"fade_s", n.fade_s},
          {"update_hz", n.update_hz},
          {"max_fraction_of_fs", n.max_fraction_of_fs},
          {"spindle_teeth", p.spindle_teeth},
          {"spindle_rpm_max", p.spindle_rpm_max},
          {"refused_rpm", refused}};
}

// Recordings made before the harmonic notches have none of this: the defaults (off) replay them.
void notch_from(const json& j, control::ControllerParams& p) {
  if (!j.contains("harmonic_notch")) return;
  const json& h = j.at("harmonic_notch");
  auto& n = p.harmonic_notch;
  n.enabled = h.at("enabled");
  n.harmonics = h.at("harmonics");
  n.bandwidth_hz = h.at("bandwidth_hz");
  n.depth_db = h.at("depth_db");
  n.slew_fraction = h.at("slew_fraction");
  n.min_hz = h.at("min_hz");
  n.fade_s = h.at("fade_s");
  n.update_hz = h.at("update_hz");
  n.max_fraction_of_fs = h.at("max_fraction_of_fs");
  p.spindle_teeth = h.at("spindle_teeth");
  p.spindle_rpm_max = h.at("spindle_rpm_max");
  for (const auto& r : h.at("refused_rpm")) {
    if (p.refused_rpm_count == control::ControllerParams::kMaxRefusedSpeeds) break;
    p.refused_rpm[p.refused_rpm_count++] = {r.at(0).get<double>(), r.at(1).get<double>()};
  }
}

// controller.speed_schedule: [rpm_min, rpm_max, gain_ns_per_m, set] per band.
json speed_bands_json(const control::ControllerParams& p) {
  json bands = json::array();
  for (std::size_t i = 0; i < p.speed_band_count; ++i) {
    const auto& b = p.speed_bands[i];
    bands.push_back({b.rpm_min, b.rpm_max, b.gain_ns_per_m, b.set});
  }
  return bands;
}

// Recordings made before the speed schedule have none: unscheduled.
void speed_bands_from(const json& j, control::ControllerParams& p) {
  for (const auto& b : j.value("speed_bands", json::array())) {
    if (p.speed_band_count == control::ControllerParams::kMaxSpeedBands) break;
    p.speed_bands[p.speed_band_count++] = {b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>(),
                                           b.at(3).get<std::size_t>()};
  }
}

}  // namespace

json to_json(const control::ControllerParams& p) {
  json sections = json::array();
  for (std::size_t i = 0; i < p.sections.count; ++i) {
    const auto& s = p.sections.sections[i];
    sections.push_back({s.b0, s.b1, s.b2, s.a1, s.a2});
  }
  return {{"fs_hz", p.fs_hz},
          {"sections", sections},
          {"sections_gain", p.sections_gain},
          {"gain_ns_per_m", p.gain_ns_per_m},
          {"gain_ramp_s", p.gain_ramp_s},
          {"settle_s", p.settle_s},
          {"polarity", p.polarity},
          {"actuator_constant_n_per_v", p.actuator_constant_n_per_v},
          {"force_limit_n", p.force_limit_n},
          {"voltage_limit_v", p.voltage_limit_v},
          {"slew_rate_v_per_s", p.slew_rate_v_per_s},
          {"harmonic_notch", notch_json(p)},
          {"speed_bands", speed_bands_json(p)}};
}

control::ControllerParams controller_params_from(const json& j) {
  control::ControllerParams p;
  p.fs_hz = j.at("fs_hz").get<double>();
  std::vector<filters::BiquadCoefficients> v;
  for (const auto& s : j.at("sections")) v.push_back({s.at(0), s.at(1), s.at(2), s.at(3), s.at(4)});
  p.sections = filters::SosCoefficients::from(v);
  p.sections_gain = j.at("sections_gain").get<double>();
  p.gain_ns_per_m = j.at("gain_ns_per_m").get<double>();
  p.gain_ramp_s = j.at("gain_ramp_s").get<double>();
  p.settle_s = j.at("settle_s").get<double>();
  p.polarity = j.at("polarity").get<int>();
  p.actuator_constant_n_per_v = j.at("actuator_constant_n_per_v").get<double>();
  p.force_limit_n = j.at("force_limit_n").get<double>();
  p.voltage_limit_v = j.at("voltage_limit_v").get<double>();
  p.slew_rate_v_per_s = j.at("slew_rate_v_per_s").get<double>();
  notch_from(j, p);
  speed_bands_from(j, p);
  return p;
}

json to_json(const SupervisorSettings& s) { return fields::to_json(s); }

json to_json(const PeriodicChirp& c) { return fields::to_json(c); }

namespace {

// A chirp recorded before its ramp or its start on command existed: none, a start time.
PeriodicChirp chirp_from(const json& t) { return fields::from_json<PeriodicChirp>(t); }

}  // namespace

PeriodicChirp excitation_from(const json& header) {
  if (header.contains("excitation")) return chirp_from(header.at("excitation").at("chirp"));
  // Recorded while the supervisor owned the chirp; none before robodamp measure existed.
  const json& s = header.at("supervisor");
  return s.contains("test_signal") ? chirp_from(s.at("test_signal")) : PeriodicChirp{};
}

SupervisorSettings supervisor_settings_from(const json& j) {
  // What a recording made before a key existed ran with: no stale ride-through, no overrun ride-through, every
  // trip latched (before recovery), growth and saturation tripping (before derating); the others' defaults.
  SupervisorSettings legacy;
  legacy.limits.zero_command_while_stale = false;
  legacy.limits.overrun_delay_margin_share = 0.0;
  legacy.limits.recovery.recoverable.clear();
  legacy.limits.derate.enabled = false;
  SupervisorSettings s = fields::from_json<SupervisorSettings>(j, legacy);
  // Recorded while the supervisor owned the chirp: its voltage limit was the chirp's; before that, none.
  if (!j.contains("command_limit_v") && j.contains("test_signal"))
    s.command_limit_v = j.at("test_signal").at("voltage_limit_v");
  return s;
}

json trips_to_json(const std::vector<Trip>& trips) { return trip_names(trips); }

std::vector<Trip> trips_from_json(const json& names) { return trips_named(names.get<std::vector<std::string>>()); }

std::vector<std::string> trip_names(const std::vector<Trip>& trips) {
  std::vector<std::string> out;
  out.reserve(trips.size());
  for (const Trip t : trips) out.emplace_back(trip_name(t));
  return out;
}

std::vector<Trip> trips_named(const std::vector<std::string>& names) {
  std::vector<Trip> out;
  for (const std::string& n : names) {
    const std::optional<Trip> t = trip_named(n);
    if (!t) throw RecordingError("the recording's supervisor.recovery.recoverable names no trip: '" + n + "'");
    out.push_back(*t);
  }
  return out;
}

json recording_header(const RecordedConfig& cfg, const Supervisor& supervisor, ClockKind clock,
                      const PeriodicChirp& excitation) {
  json fields = json::array();
  for (const auto& f : frame_fields())
    fields.push_back({{"name", f.name}, {"type", to_string(f.type)}, {"offset", f.offset}, {"unit", f.unit}});
  json states = json::array(), trips = json::array(), commands = json::array();
  for (int i = 0; i <= static_cast<int>(State::kFault); ++i) states.push_back(to_string(static_cast<State>(i)));
  for (std::size_t i = 0; i < kTripCount; ++i) trips.push_back(to_string(static_cast<Trip>(i)));
  for (int i = 0; i <= static_cast<int>(kLastCommandKind); ++i)
    commands.push_back(to_string(static_cast<CommandKind>(i)));
  json sets = json::array();  // index 0 is controller_params with the supervisor's verdict
  for (std::size_t i = 1; i < supervisor.parameter_sets().size(); ++i) {
    const ParameterSet& p = supervisor.parameter_sets()[i];
    sets.push_back({{"params", to_json(p.params)},
                    {"analysis_stable", p.analysis_stable},
                    {"max_stable_gain_ns_per_m", p.max_stable_gain_ns_per_m},
                    {"delay_margin_s", p.delay_margin_s}});
  }
  // A virtual-clock run has no wall time in it: its file carries none, so the same run gives the same
  // bytes (docs/recording_format.md).
  char created[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  if (clock == ClockKind::kWall) std::strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return {{"format", "robodamp-recording"},
          {"format_version", kRecordingFormatVersion},
          {"robodamp_version", version()},
          {"git_commit", git_commit()},
          {"created_utc", clock == ClockKind::kWall ? json(created) : json(nullptr)},
          {"byte_order", "little"},
          {"frame_bytes", sizeof(TelemetryFrame)},
          {"fields", fields},
          {"flag_bits",
           {"fresh", "sensor_ok", "actuator_ok", "actuator_saturated", "amplifier_ready", "amplifier_fault", "overrun",
            "shutdown", "amplifier_enable", "saturated"}},
          {"states", states},
          {"trips", trips},
          {"commands", commands},
          {"clock", to_string(clock)},
          {"rate_hz", cfg.rate_hz},
          {"config_source", cfg.source},
          {"config_yaml", cfg.yaml},
          {"controller_params", to_json(supervisor.initial_params())},
          {"parameter_sets", sets},
          {"supervisor", to_json(supervisor.settings())},
          {"excitation", {{"chirp", to_json(excitation)}}}};
}

Recorder::Recorder(const std::string& path, const json& header) : path_(path), buffer_(1 << 20) {
  f_ = std::fopen(path.c_str(), "wb");
  if (f_ == nullptr) throw RecordingError("cannot open " + path + " for writing: " + std::strerror(errno));
  std::setvbuf(f_, buffer_.data(), _IOFBF, buffer_.size());
  const std::string text = header.dump();
  const auto version = kRecordingFormatVersion;
  const auto length = static_cast<std::uint32_t>(text.size());
  if (std::fwrite(kRecordingMagic, 1, 8, f_) != 8 || std::fwrite(&version, 4, 1, f_) != 1 ||
      std::fwrite(&length, 4, 1, f_) != 1 || std::fwrite(text.data(), 1, text.size(), f_) != text.size())
    throw RecordingError("cannot write the header of " + path + ": " + std::strerror(errno));
}

Recorder::~Recorder() { close(); }

void Recorder::write(const TelemetryFrame& f) {
  if (f_ == nullptr) return;
  if (std::fwrite(&f, sizeof f, 1, f_) == 1)
    ++frames_;
  else
    ++write_errors_;
}

void Recorder::close() {
  if (f_ == nullptr) return;
  if (std::fclose(f_) != 0) ++write_errors_;
  f_ = nullptr;
}

Recording read_recording(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw RecordingError(path + ": cannot open: " + std::strerror(errno));
  struct Closer {
    std::FILE* f;
    ~Closer() { std::fclose(f); }
  } closer{f};
  char magic[8];
  std::uint32_t version = 0, length = 0;
  if (std::fread(magic, 1, 8, f) != 8 || std::memcmp(magic, kRecordingMagic, 8) != 0)
    throw RecordingError(path + ": not a robodamp recording (magic RDAMPREC missing)");
  if (std::fread(&version, 4, 1, f) != 1 || version != kRecordingFormatVersion)
    throw RecordingError(path + ": recording format version " + std::to_string(version) + ", this build reads " +
                         std::to_string(kRecordingFormatVersion));
  if (std::fread(&length, 4, 1, f) != 1 || length > (64U << 20))
    throw RecordingError(path + ": header length missing or implausible");
  std::string text(length, '\0');
  if (std::fread(text.data(), 1, length, f) != length) throw RecordingError(path + ": header truncated");
  Recording r;
  try {
    r.header = json::parse(text);
  } catch (const json::exception& e) {
    throw RecordingError(path + ": header is not valid JSON: " + e.what());
  }
  if (r.header.value("frame_bytes", 0U) != sizeof(TelemetryFrame))
    throw RecordingError(path + ": frame size " + std::to_string(r.header.value("frame_bytes", 0U)) +
                         " bytes, this build's frame is " + std::to_string(sizeof(TelemetryFrame)));
  TelemetryFrame fr;
  std::size_t got = 0;
  while ((got = std::fread(&fr, 1, sizeof fr, f)) == sizeof fr) r.frames.push_back(fr);
  r.trailing_bytes = got;
  return r;
}

void write_csv(const Recording& r, std::FILE* out) {
  const auto& fields = frame_fields();
  for (std::size_t i = 0; i < fields.size(); ++i)
    std::fprintf(out, "%s%.*s", i ? "," : "", static_cast<int>(fields[i].name.size()), fields[i].name.data());
  std::fprintf(out, ",state_name,trip_name\n");
  for (const auto& f : r.frames) {
    const auto* base = reinterpret_cast<const unsigned char*>(&f);
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const unsigned char* p = base + fields[i].offset;
      if (i) std::fputc(',', out);
      switch (fields[i].type) {
        case FieldType::kU8:
          std::fprintf(out, "%u", static_cast<unsigned>(*p));
          break;
        case FieldType::kU16: {
          std::uint16_t v;
          std::memcpy(&v, p, 2);
          std::fprintf(out, "%u", static_cast<unsigned>(v));
          break;
        }
        case FieldType::kU32: {
          std::uint32_t v;
          std::memcpy(&v, p, 4);
          std::fprintf(out, "%u", v);
          break;
        }
        case FieldType::kU64: {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          std::fprintf(out, "%llu", static_cast<unsigned long long>(v));
          break;
        }
        case FieldType::kF32: {
          float v;
          std::memcpy(&v, p, 4);
          std::fprintf(out, "%.9g", static_cast<double>(v));
          break;
        }
        case FieldType::kF64: {
          double v;
          std::memcpy(&v, p, 8);
          std::fprintf(out, "%.17g", v);
          break;
        }
      }
    }
    std::fprintf(out, ",%s,%s\n", to_string(static_cast<State>(f.state)), to_string(static_cast<Trip>(f.trip)));
  }
}

ReplayResult replay(const Recording& r) {
  ReplayResult res;
  Supervisor sup(supervisor_settings_from(r.header.at("supervisor")),
                 controller_params_from(r.header.at("controller_params")));
  ExcitationClock excitation(excitation_from(r.header));
  for (const auto& p : r.header.value("parameter_sets", json::array()))
    sup.add_parameter_set({controller_params_from(p.at("params")), p.at("analysis_stable").get<bool>(),
                           p.at("max_stable_gain_ns_per_m").get<double>(), p.value("delay_margin_s", 0.0)});
  for (const auto& f : r.frames) {
    TickInput in = tick_input(f);
    in.excitation_v = excitation.next_v(in.dt_s);
    if (in.command.kind == CommandKind::kStartExcitation) excitation.start_next_tick();
    const TickOutput out = sup.step(in);
    ++res.frames;
    // Bit for bit: the same double, not only an equal one (a replay reproduces the run exactly).
    const bool same = std::bit_cast<std::uint64_t>(out.command_v) == std::bit_cast<std::uint64_t>(f.command_v) &&
                      std::bit_cast<std::uint64_t>(out.controller_v) == std::bit_cast<std::uint64_t>(f.controller_v) &&
                      static_cast<std::uint8_t>(out.state) == f.state && static_cast<std::uint8_t>(out.trip) == f.trip;
    if (!same && res.mismatches++ == 0) {
      res.first_mismatch_tick = f.tick;
      res.first_recorded_v = f.command_v;
      res.first_replayed_v = out.command_v;
    }
  }
  res.final_state = to_string(sup.state());
  res.final_trip = to_string(sup.latched_trip());
  return res;
}

}  // namespace robodamp::rt
