// long: every key of a cell's configuration with its unit and range, section by section; the sections with their own files are split out (can, modbus, spindle, pose schedule)
#include "config/config.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <complex>
#include <fstream>
#include <set>
#include <sstream>

#include "config/robot_model_config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::Diagnostics;
using detail::format_number;
using detail::MapReader;
using detail::present;
using detail::Range;
using detail::read_bool;
using detail::read_int;
using detail::read_mode;
using detail::read_sign;

std::string Problem::to_string() const {
  std::ostringstream os;
  os << file;
  if (mark.line > 0) os << ':' << mark.line << ':' << mark.column;
  os << ": " << key << (message.rfind("= ", 0) == 0 ? " " : ": ") << message;
  return os.str();
}

namespace {
std::string summarise(const std::vector<Problem>& problems) {
  std::string s = std::to_string(problems.size()) + " configuration problem(s):";
  for (const auto& p : problems) s += "\n  " + p.to_string();
  return s;
}
}  // namespace

std::vector<Problem> located(std::vector<Problem> problems, const std::string& yaml_text) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception&) {}
  for (Problem& p : problems) {
    if (p.mark.line > 0) continue;
    p.mark = {1, 1};
    YAML::Node node = root;
    std::size_t start = 0;
    // Walk "robot.frfs[2].modes": a name, then any [index], segment by segment.
    while (start < p.key.size() && node && node.IsMap()) {
      std::size_t end = p.key.find('.', start);
      if (end == std::string::npos) end = p.key.size();
      const std::string seg = p.key.substr(start, end - start);
      const std::size_t bracket = seg.find('[');
      YAML::Node next;
      try {
        next = node[seg.substr(0, bracket)];
        if (next && bracket != std::string::npos && next.IsSequence()) {
          const std::size_t idx = std::strtoul(seg.c_str() + bracket + 1, nullptr, 10);
          if (idx < next.size()) next = next[idx];
        }
      } catch (const YAML::Exception&) {
        break;
      }
      if (!next || next.Mark().is_null()) break;
      p.mark = detail::to_mark(next.Mark());
      node = next;
      start = end + 1;
    }
  }
  return problems;
}

ConfigError::ConfigError(std::vector<Problem> problems)
    : std::runtime_error(summarise(problems)), problems_(std::move(problems)) {}

const char* to_string(BlockKind kind) {
  switch (kind) {
    case BlockKind::kLowpass2:
      return "lowpass2";
    case BlockKind::kHighpass2:
      return "highpass2";
    case BlockKind::kNotch:
      return "notch";
    case BlockKind::kIntegrator:
      return "integrator";
    case BlockKind::kCompensator:
      return "compensator";
  }
  return "?";
}

std::optional<BlockKind> block_kind_from(const std::string& name) {
  for (BlockKind k : {BlockKind::kLowpass2, BlockKind::kHighpass2, BlockKind::kNotch, BlockKind::kIntegrator,
                      BlockKind::kCompensator})
    if (name == to_string(k)) return k;
  return std::nullopt;
}

const char* to_string(CompensatorModel model) {
  switch (model) {
    case CompensatorModel::kC1:
      return "c1";
    case CompensatorModel::kC2:
      return "c2";
    case CompensatorModel::kC3:
      return "c3";
    case CompensatorModel::kRational:
      return "rational";
  }
  return "?";
}

const char* to_string(Mounting mounting) { return mounting == Mounting::kHorizontal ? "horizontal" : "vertical"; }

namespace {

// Limits shared by several keys. The loop rate range is the product's (1-20 kHz).
constexpr double kMinRateHz = 1000.0;
constexpr double kMaxRateHz = 20000.0;

// Frequencies of digital blocks must stay below Nyquist of the loop rate; if the rate itself is
// invalid, the widest possible Nyquist is used and the rate's own problem is reported.
Range below_nyquist(std::optional<double> rate_hz) {
  const double nyq = 0.5 * rate_hz.value_or(kMaxRateHz);
  return {"Hz", 0.0,  nyq,
          true, true, rate_hz ? "below Nyquist, loop.rate_hz = " + format_number(*rate_hz) + " Hz" : "below Nyquist"};
}

const Range kDamping{"(dimensionless)", 0.0, 10.0, true, false};

LoopConfig read_loop(MapReader& top, std::optional<double>& rate) {
  MapReader r(top.diagnostics(), top.child("loop", true, "map with rate_hz"), "loop", top.mark());
  LoopConfig c;
  rate = r.number("rate_hz", {"Hz", kMinRateHz, kMaxRateHz});
  if (rate) c.rate_hz = *rate;
  if (auto v = r.choice("clock", {"wall", "virtual"}, "wall"))
    c.clock = *v == "wall" ? ClockKind::kWall : ClockKind::kVirtual;
  r.finish();
  return c;
}

const Range kLocationId{"(location id)", 1, 64};

ActuatorConfig read_actuator(MapReader& top, std::optional<double> rate) {
  MapReader r(top.diagnostics(), top.child("actuator", true, "map, Eq. 3 parameters"), "actuator", top.mark());
  ActuatorConfig c;
  if (auto m = r.choice("mounting", {"horizontal", "vertical"}))
    c.mounting = *m == "horizontal" ? Mounting::kHorizontal : Mounting::kVertical;
  if (auto v = r.number("constant_n_per_v", {"N/V", 0.0, 1000.0, true})) c.constant_n_per_v = *v;
  if (auto v = r.number("natural_freq_hz", below_nyquist(rate))) c.natural_freq_hz = *v;
  if (auto v = r.number("damping_ratio", kDamping)) c.damping_ratio = *v;
  if (auto v = r.number("delay_s", {"s", 0.0, 0.1})) c.delay_s = *v;
  if (auto v = r.number("force_limit_n", {"N", 0.0, 10000.0, true})) c.force_limit_n = *v;
  if (auto v = read_int(r, "location", kLocationId, c.location)) c.location = *v;
  r.finish();
  return c;
}

AmplifierConfig read_amplifier(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("amplifier", true, "map with voltage_limit_v, slew_rate_v_per_s"),
              "amplifier", top.mark());
  AmplifierConfig c;
  if (auto v = r.number("voltage_limit_v", {"V", 0.0, 100.0, true})) c.voltage_limit_v = *v;
  if (auto v = r.number("slew_rate_v_per_s", {"V/s", 0.0, 1e8, true})) c.slew_rate_v_per_s = *v;
  r.finish();
  return c;
}

std::optional<BlockConfig> read_block(Diagnostics& d, const YAML::Node& node, const std::string& key,
                                      std::optional<double> rate) {
  const std::size_t before = d.problems().size();
  MapReader r(d, node, key, node.Mark());
  BlockConfig b;
  b.key = key;
  b.mark = detail::to_mark(node.Mark());
  const auto kind = r.choice("kind", {"lowpass2", "highpass2", "notch", "integrator", "compensator"});
  b.name = r.text("name", std::string()).value_or("");
  if (auto p = r.number("prewarp_hz", below_nyquist(rate), -1.0); p && *p >= 0.0) b.prewarp_hz = *p;
  if (!kind) return std::nullopt;  // its other keys cannot be judged without a kind
  b.kind = *block_kind_from(*kind);
  if (b.kind == BlockKind::kLowpass2 || b.kind == BlockKind::kHighpass2) {
    if (auto v = r.number("cutoff_hz", below_nyquist(rate))) b.cutoff_hz = *v;
    if (auto v = r.number("damping_ratio", kDamping, 0.707)) b.damping_ratio = *v;
  } else if (b.kind == BlockKind::kNotch) {
    if (auto v = r.number("center_hz", below_nyquist(rate))) b.center_hz = *v;
    if (auto v = r.number("bandwidth_hz", below_nyquist(rate))) b.bandwidth_hz = *v;
  } else if (b.kind == BlockKind::kIntegrator) {
    if (auto v = r.number("leak_hz", {"Hz", 0.0, 1.0, false, false, "0 = ideal, realised with the high-pass"}, 0.0))
      b.leak_hz = *v;
  } else {
    const auto model = r.choice("model", {"c1", "c2", "c3", "rational"});
    if (model == "c1") {
      b.model = CompensatorModel::kC1;
      if (auto v = r.number("corner_hz", below_nyquist(rate), 0.5)) b.corner_hz = *v;
      if (auto v = r.number("corner_damping_ratio", kDamping, 1.0)) b.corner_damping_ratio = *v;
    } else if (model == "c2") {
      b.model = CompensatorModel::kC2;
    } else if (model == "c3") {
      b.model = CompensatorModel::kC3;
    } else if (model == "rational") {
      b.model = CompensatorModel::kRational;
      auto num = r.number_list("numerator", "coefficients of s, highest power first");
      auto den = r.number_list("denominator", "coefficients of s, highest power first");
      if (num) b.numerator = *num;
      if (den) {
        b.denominator = *den;
        if (den->front() == 0.0)
          d.add(node.Mark(), key + ".denominator", "leading coefficient is 0 (give the highest power first)");
      }
    }
  }
  r.finish();
  return d.problems().size() == before ? std::optional(b) : std::nullopt;
}

ControllerConfig read_controller(MapReader& top, std::optional<double> rate) {
  Diagnostics& d = top.diagnostics();
  MapReader r(d, top.child("controller", true, "map with gain, polarity and chain"), "controller", top.mark());
  ControllerConfig c;
  if (auto v = r.number("gain_ns_per_m", {"N s/m", 0.0, 1e5})) c.gain_ns_per_m = *v;
  if (auto v = r.number("gain_ramp_s", {"s", 0.0, 60.0}, 0.5)) c.gain_ramp_s = *v;
  const YAML::Node pol = r.child("polarity", true, "+1 or -1, settled by the closed-loop analysis");
  if (pol.IsDefined() && !pol.IsNull()) {
    int p = 0;
    if (!pol.IsScalar() || !YAML::convert<int>::decode(pol, p) || (p != 1 && p != -1))
      d.add(pol.Mark(), "controller.polarity",
            "= '" + (pol.IsScalar() ? pol.Scalar() : std::string("?")) + "' is not allowed: +1 or -1");
    else
      c.polarity = p;
  }
  if (auto v = r.number("match_freq_hz", below_nyquist(rate), -1.0); v && *v >= 0.0) c.match_freq_hz = *v;
  c.harmonic_notch = detail::read_harmonic_notch(r, rate);
  c.speed_schedule = detail::read_speed_schedule(r, rate);
  const YAML::Node chain = r.child("chain", true, "list of blocks (Eq. 8)");
  if (chain.IsDefined() && !chain.IsNull()) {
    if (!chain.IsSequence() || chain.size() == 0) {
      d.add(chain.Mark(), "controller.chain", "must be a non-empty list of blocks");
    } else {
      std::set<std::string> names;
      int counts[5] = {};
      for (std::size_t i = 0; i < chain.size(); ++i) {
        const std::string key = "controller.chain[" + std::to_string(i) + "]";
        auto b = read_block(d, chain[i], key, rate);
        if (!b) {
          // Still count its kind, so a block with a bad value is not also reported as missing.
          const YAML::Node item = chain[i];
          const YAML::Node kind = item.IsMap() ? YAML::Node(item["kind"]) : YAML::Node();
          if (kind.IsDefined() && kind.IsScalar())
            if (auto k = block_kind_from(kind.Scalar())) ++counts[static_cast<int>(*k)];
          continue;
        }
        const int n = ++counts[static_cast<int>(b->kind)];
        if (b->name.empty()) b->name = std::string(to_string(b->kind)) + (n > 1 ? "_" + std::to_string(n) : "");
        if (!names.insert(b->name).second) d.add(chain[i].Mark(), key + ".name", "= '" + b->name + "' is used twice");
        c.chain.push_back(*b);
      }
      const YAML::Mark m = chain.Mark();
      if (counts[static_cast<int>(BlockKind::kIntegrator)] != 1)
        d.add(m, "controller.chain",
              "needs exactly one integrator block (DVF feeds back velocity, Eq. 8), found " +
                  std::to_string(counts[static_cast<int>(BlockKind::kIntegrator)]));
      for (const auto& b : c.chain)
        if (b.kind == BlockKind::kIntegrator && b.leak_hz == 0.0 &&
            counts[static_cast<int>(BlockKind::kHighpass2)] == 0)
          d.add(b.mark, b.key + ".leak_hz",
                "= 0 Hz with no highpass2 in the chain: an ideal integrator would drift without bound on a sensor "
                "offset; add a highpass2 or set leak_hz (allowed 0 < value <= 1 Hz)");
    }
  }
  r.finish();
  return c;
}

RobotConfig read_robot(MapReader& top, std::optional<double> rate) {
  Diagnostics& d = top.diagnostics();
  RobotConfig robot;
  const YAML::Node node = top.child("robot", false, "");
  if (!node.IsDefined() || node.IsNull()) return robot;
  MapReader r(d, node, "robot", top.mark());
  const YAML::Node locs = r.child("locations", false, "");
  if (locs.IsDefined() && !locs.IsNull()) {
    if (!locs.IsSequence() || locs.size() == 0) d.add(locs.Mark(), "robot.locations", "must be a non-empty list");
    std::set<int> ids;
    for (std::size_t i = 0; locs.IsSequence() && i < locs.size(); ++i) {
      const std::string key = "robot.locations[" + std::to_string(i) + "]";
      MapReader lr(d, locs[i], key, locs.Mark());
      LocationConfig l;
      if (auto v = read_int(lr, "id", kLocationId)) {
        l.id = *v;
        if (!ids.insert(l.id).second)
          d.add(locs[i].Mark(), key + ".id", "= " + std::to_string(l.id) + " is used twice");
      }
      l.name = lr.text("name", "location " + std::to_string(l.id)).value_or("");
      if (auto v = read_sign(lr, "axis_sign", 1)) l.axis_sign = *v;
      lr.finish();
      robot.locations.push_back(l);
    }
  }
  const YAML::Node frfs = r.child("frfs", true, "list of FRFs, each a sum of modes (Eq. 1)");
  if (frfs.IsDefined() && !frfs.IsNull()) {
    if (!frfs.IsSequence()) d.add(frfs.Mark(), "robot.frfs", "must be a list");
    std::set<std::string> names;
    std::set<std::pair<int, int>> paths;
    for (std::size_t i = 0; frfs.IsSequence() && i < frfs.size(); ++i) {
      const std::string key = "robot.frfs[" + std::to_string(i) + "]";
      MapReader fr(d, frfs[i], key, frfs.Mark());
      FrfConfig f;
      f.name = fr.text("name", std::nullopt).value_or("");
      if (!names.insert(f.name).second) d.add(frfs[i].Mark(), key + ".name", "= '" + f.name + "' is used twice");
      const auto g = read_int(fr, "response_location", kLocationId);
      const auto h = read_int(fr, "excitation_location", kLocationId);
      if (g) f.response_location = *g;
      if (h) f.excitation_location = *h;
      if (g && h && !paths.insert({*g, *h}).second)
        d.add(frfs[i].Mark(), key,
              "a second FRF for response " + std::to_string(*g) + ", excitation " + std::to_string(*h) +
                  ": one FRF per path");
      const YAML::Node modes = fr.child("modes", true, "list of modes");
      if (modes.IsDefined() && (!modes.IsSequence() || modes.size() == 0))
        d.add(modes.Mark().is_null() ? frfs[i].Mark() : modes.Mark(), key + ".modes",
              "must be a non-empty list of modes");
      for (std::size_t k = 0; modes.IsSequence() && k < modes.size(); ++k) {
        MapReader mr(d, modes[k], key + ".modes[" + std::to_string(k) + "]", modes.Mark());
        f.modes.push_back(read_mode(mr, below_nyquist(rate)));
      }
      fr.finish();
      robot.frfs.push_back(std::move(f));
    }
  }
  r.finish();
  // Without a locations list every location is in the common frame.
  if (robot.locations.empty()) {
    std::set<int> ids;
    for (const auto& f : robot.frfs) ids.insert({f.response_location, f.excitation_location});
    for (int id : ids) robot.locations.push_back({id, "location " + std::to_string(id), 1});
  } else {
    for (std::size_t i = 0; i < robot.frfs.size(); ++i)
      for (int id : {robot.frfs[i].response_location, robot.frfs[i].excitation_location})
        if (!find_location(robot, id))
          d.add(r.mark(), "robot.frfs[" + std::to_string(i) + "]",
                "uses location " + std::to_string(id) + ", which robot.locations does not list");
  }
  return robot;
}

SensorConfig read_sensor(MapReader& top, std::optional<double> rate) {
  MapReader r(top.diagnostics(), top.child("sensor", false, ""), "sensor", top.mark());
  SensorConfig c;
  if (auto v = read_int(r, "location", kLocationId, c.location)) c.location = *v;
  if (auto v = r.number("sensitivity_mv_per_g", {"mV/g", 0.0, 1e5, true}, c.sensitivity_mv_per_g))
    c.sensitivity_mv_per_g = *v;
  if (auto v = r.number("range_g", {"g", 0.0, 1e5, true}, c.range_g)) c.range_g = *v;
  if (auto v = r.number("noise_density_ug_per_rthz", {"ug/sqrt(Hz)", 0.0, 1e6}, c.noise_density_ug_per_rthz))
    c.noise_density_ug_per_rthz = *v;
  if (auto v = r.number("highpass_hz", {"Hz", 0.0, 0.5 * rate.value_or(kMaxRateHz), false, true, "0 = DC coupled"},
                        c.highpass_hz))
    c.highpass_hz = *v;
  if (auto v = read_int(r, "adc_bits", {"bits", 8, 32}, c.adc_bits)) c.adc_bits = *v;
  if (auto v = r.number("adc_range_v", {"V", 0.0, 1000.0, true}, c.adc_range_v)) c.adc_range_v = *v;
  r.finish();
  return c;
}

PlantConfig read_plant(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("plant", false, ""), "plant", top.mark());
  PlantConfig c;
  if (auto v = read_int(r, "oversampling", {"(internal steps per loop period)", 1, 64}, c.oversampling))
    c.oversampling = *v;
  if (auto v = read_int(r, "actuator_wiring", {"(1 as configured, -1 leads swapped)", -1, 1}, c.actuator_wiring)) {
    if (*v == 0)
      r.diagnostics().add(r.mark(), "plant.actuator_wiring",
                          "= 0 is not a wiring: allowed 1 (as configured) or -1 (leads swapped)");
    else
      c.actuator_wiring = *v;
  }
  r.finish();
  return c;
}

DisturbanceConfig read_disturbances(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("disturbances", false, ""), "disturbances", top.mark());
  DisturbanceConfig c;
  if (auto v = r.choice("drives_on", {"true", "false"}, "true")) c.drives_on = *v == "true";
  if (auto v = r.number("drive_vibration_hz", {"Hz", 0.0, 100.0, true}, c.drive_vibration_hz))
    c.drive_vibration_hz = *v;
  if (auto v = r.number("drive_vibration_mps2", {"m/s^2", 0.0, 100.0}, c.drive_vibration_mps2))
    c.drive_vibration_mps2 = *v;
  if (auto v = read_int(r, "drive_vibration_location", kLocationId, c.drive_vibration_location))
    c.drive_vibration_location = *v;
  if (auto v = r.number("seed", {"(integer)", 0.0, 9007199254740992.0}, 1.0)) c.seed = static_cast<std::uint64_t>(*v);
  r.finish();
  return c;
}

AnalysisConfig read_analysis(MapReader& top, std::optional<double> rate) {
  MapReader r(top.diagnostics(), top.child("analysis", false, ""), "analysis", top.mark());
  AnalysisConfig c;
  const Range band = below_nyquist(rate);
  if (auto v = r.number("band_min_hz", band, c.band_min_hz)) c.band_min_hz = *v;
  if (auto v = r.number("band_max_hz", band, c.band_max_hz)) c.band_max_hz = *v;
  if (c.band_max_hz <= c.band_min_hz)
    r.diagnostics().add(r.mark(), "analysis.band_max_hz",
                        "= " + format_number(c.band_max_hz) +
                            " Hz must be above analysis.band_min_hz = " + format_number(c.band_min_hz) + " Hz");
  r.finish();
  return c;
}

BenchConfig read_bench(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("bench", false, ""), "bench", top.mark());
  BenchConfig c;
  if (auto v = r.number("impact_peak_n", {"N", 0.0, 1e6, true}, c.impact_peak_n)) c.impact_peak_n = *v;
  if (auto v = r.number("impact_duration_ms", {"ms", 0.05, 50.0}, c.impact_duration_ms)) c.impact_duration_ms = *v;
  if (auto v = r.number("saturating_impact_peak_n", {"N", 0.0, 1e7, true}, c.saturating_impact_peak_n))
    c.saturating_impact_peak_n = *v;
  if (auto v = r.number("saturating_impact_duration_ms", {"ms", 0.05, 50.0}, c.saturating_impact_duration_ms))
    c.saturating_impact_duration_ms = *v;
  if (auto v = read_int(r, "averages", {"(impacts per test)", 1, 1000}, c.averages)) c.averages = *v;
  if (auto v = r.number("record_s", {"s", 0.5, 600.0}, c.record_s)) c.record_s = *v;
  if (auto v = read_int(r, "zero_pad", {"(x record length)", 1, 64}, c.zero_pad)) c.zero_pad = *v;
  if (auto v = r.number("measurement_highpass_hz", {"Hz", 0.0, 10.0}, c.measurement_highpass_hz))
    c.measurement_highpass_hz = *v;
  if (present(r.child("sweep_gain_factors", false, ""))) {
    if (auto v = r.number_list("sweep_gain_factors", "x the predicted maximum stable gain")) {
      c.sweep_gain_factors = *v;
      for (std::size_t i = 0; i < v->size(); ++i)
        if (!((*v)[i] > 0.0 && (*v)[i] <= 100.0))
          r.diagnostics().add(r.mark(), "bench.sweep_gain_factors[" + std::to_string(i) + "]",
                              "= " + format_number((*v)[i]) + " is out of range: allowed 0 < value <= 100 (x K_max)");
    }
  }
  if (auto v = r.number("sweep_duration_s", {"s", 1.0, 3600.0}, c.sweep_duration_s)) c.sweep_duration_s = *v;
  r.finish();
  return c;
}

RealtimeConfig read_realtime(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("realtime", false, ""), "realtime", top.mark());
  RealtimeConfig c;
  if (auto v = read_int(r, "priority", {"(SCHED_FIFO priority, 0 = SCHED_OTHER)", 0, 99}, c.priority)) c.priority = *v;
  if (auto v = read_int(r, "cpu", {"(CPU index, -1 = any)", -1, 1023}, c.cpu)) c.cpu = *v;
  if (auto v = read_bool(r, "lock_memory", c.lock_memory)) c.lock_memory = *v;
  if (auto v = read_int(r, "stack_prefault_kib", {"KiB", 0, 65536}, c.stack_prefault_kib)) c.stack_prefault_kib = *v;
  if (auto v = read_bool(r, "hold_cpu_dma_latency", c.hold_cpu_dma_latency)) c.hold_cpu_dma_latency = *v;
  r.finish();
  return c;
}

RecoveryConfig read_recovery(MapReader& top) {
  const YAML::Node node = top.child("recovery", false, "");
  MapReader r(top.diagnostics(), node, "supervision.recovery", top.mark());
  RecoveryConfig c;
  if (present(node) && node.IsMap() && present(node["recoverable"])) {
    const YAML::Node list = node["recoverable"];
    c.recoverable.clear();
    if (!list.IsSequence()) {
      top.diagnostics().add(
          list.Mark(), "supervision.recovery.recoverable",
          "must be a list of trip classes (any of: overruns, sensor_stale, sample_invalid, sensor_driver, "
          "actuator_driver, amplifier_not_ready; [] = every trip latches)");
    } else {
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string key = "supervision.recovery.recoverable[" + std::to_string(i) + "]";
        const std::string name = list[i].IsScalar() ? list[i].Scalar() : std::string();
        const std::optional<rt::Trip> trip = rt::trip_named(name);
        if (!trip || !rt::may_recover(*trip))
          top.diagnostics().add(
              list[i].Mark(), key,
              "= '" + name +
                  "' cannot recover by itself: allowed are overruns, sensor_stale, sample_invalid, "
                  "sensor_driver, actuator_driver, amplifier_not_ready (instability, saturation, amplifier_fault, "
                  "pose_out_of_map and signal always latch)");
        else if (std::find(c.recoverable.begin(), c.recoverable.end(), *trip) != c.recoverable.end())
          top.diagnostics().add(list[i].Mark(), key, "= '" + name + "' is listed twice");
        else
          c.recoverable.push_back(*trip);
      }
    }
  }
  (void)r.child("recoverable", false, "");  // read above; known to finish()
  if (auto v = r.number("cool_down_s", {"s", 0.0, 3600.0}, c.cool_down_s)) c.cool_down_s = *v;
  if (auto v = r.number("healthy_for_s", {"s", 0.0, 3600.0}, c.healthy_for_s)) c.healthy_for_s = *v;
  if (auto v = read_int(r, "max_recoveries", {"(recoveries)", 0, 1000}, c.max_recoveries)) c.max_recoveries = *v;
  if (auto v = r.number("window_s", {"s", 1.0, 604800.0}, c.window_s)) c.window_s = *v;
  if (auto v = r.number("probation_s", {"s", 0.0, 86400.0}, c.probation_s)) c.probation_s = *v;
  r.finish();
  return c;
}

DerateConfig read_derate(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("derate", false, ""), "supervision.derate", top.mark());
  DerateConfig c;
  if (auto v = read_bool(r, "enabled", c.enabled)) c.enabled = *v;
  if (auto v = read_int(r, "probe_blocks", {"(instability blocks)", 1, 1000}, c.probe_blocks)) c.probe_blocks = *v;
  if (auto v = r.number("probe_factor", {"(x K)", 0.0, 1.0, false, true}, c.probe_factor)) c.probe_factor = *v;
  if (auto v = r.number("hold_factor", {"(x K)", 0.0, 1.0, false, true}, c.hold_factor)) c.hold_factor = *v;
  if (auto v = r.number("probe_ramp_s", {"s", 0.0, 1.0}, c.probe_ramp_s)) c.probe_ramp_s = *v;
  if (auto v = r.number("quiet_s", {"s", 0.0, 600.0}, c.quiet_s)) c.quiet_s = *v;
  if (auto v = r.number("restore_s", {"s", 0.0, 600.0}, c.restore_s)) c.restore_s = *v;
  if (auto v = r.number("saturation_factor", {"(ratio)", 0.0, 1.0, true, true}, c.saturation_factor))
    c.saturation_factor = *v;
  if (auto v = r.number("min_factor", {"(x K)", 0.0, 1.0, true, true}, c.min_factor)) c.min_factor = *v;
  r.finish();
  return c;
}

SupervisionConfig read_supervision(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("supervision", false, ""), "supervision", top.mark());
  SupervisionConfig c;
  const Range cycles{"(loop ticks)", 1, 1e6};
  if (auto v = read_int(r, "stale_sensor_cycles", cycles, c.stale_sensor_cycles)) c.stale_sensor_cycles = *v;
  if (auto v = read_int(r, "invalid_sample_cycles", cycles, c.invalid_sample_cycles)) c.invalid_sample_cycles = *v;
  if (auto v = r.number("sample_limit_mps2", {"m/s^2", 0.0, 1e7, false, false, "0 = the sensor's range"},
                        c.sample_limit_mps2))
    c.sample_limit_mps2 = *v;
  if (auto v = read_int(r, "overrun_cycles", cycles, c.overrun_cycles)) c.overrun_cycles = *v;
  if (auto v = r.number("overrun_delay_margin_share",
                        {"(share of the delay margin)", 0.0, 1.0, false, false, "0 = overrun_cycles alone"},
                        c.overrun_delay_margin_share))
    c.overrun_delay_margin_share = *v;
  if (auto v = r.number("saturation_window_s", {"s", 0.001, 10.0}, c.saturation_window_s)) c.saturation_window_s = *v;
  if (auto v = r.number("saturation_duty_max", {"(fraction of the window)", 0.0, 1.0, true}, c.saturation_duty_max))
    c.saturation_duty_max = *v;
  if (auto v = r.number("instability_block_s", {"s", 0.005, 10.0}, c.instability_block_s)) c.instability_block_s = *v;
  if (auto v = read_int(r, "instability_blocks", {"(blocks)", 2, 1000}, c.instability_blocks))
    c.instability_blocks = *v;
  if (auto v = r.number("instability_growth_factor", {"(ratio)", 1.0, 1e6, true}, c.instability_growth_factor))
    c.instability_growth_factor = *v;
  if (auto v = r.number("instability_floor_v", {"V", 0.0, 100.0}, c.instability_floor_v)) c.instability_floor_v = *v;
  if (auto v = r.number("trip_ramp_s", {"s", 0.0, 1.0}, c.trip_ramp_s)) c.trip_ramp_s = *v;
  if (auto v = read_int(r, "arming_live_cycles", cycles, c.arming_live_cycles)) c.arming_live_cycles = *v;
  if (auto v = r.number("arm_retry_s", {"s", 0.001, 60.0}, c.arm_retry_s)) c.arm_retry_s = *v;
  if (auto v = r.number("arm_deadline_s", {"s", 0.01, 86400.0}, c.arm_deadline_s)) c.arm_deadline_s = *v;
  if (auto v = r.number("amplifier_ready_timeout_s", {"s", 0.0, 60.0}, c.amplifier_ready_timeout_s))
    c.amplifier_ready_timeout_s = *v;
  if (auto v = r.number("max_gain_fraction", {"(x maximum stable K)", 0.0, 1.0, true}, c.max_gain_fraction))
    c.max_gain_fraction = *v;
  c.recovery = read_recovery(r);
  c.derate = read_derate(r);
  r.finish();
  return c;
}

TelemetryConfig read_telemetry(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("telemetry", false, ""), "telemetry", top.mark());
  TelemetryConfig c;
  if (auto v = read_int(r, "ring_frames", {"(frames, a power of two)", 1024, 1 << 24}, c.ring_frames)) {
    if ((*v & (*v - 1)) != 0)
      r.diagnostics().add(r.mark(), "telemetry.ring_frames", "= " + std::to_string(*v) + " must be a power of two");
    else
      c.ring_frames = *v;
  }
  r.finish();
  return c;
}

// A CAN identifier: decimal or 0x hex, 11 bits (or 29 with extended_id).
std::optional<std::uint32_t> read_can_id(MapReader& r, bool extended) {
  const YAML::Node n = r.child("id", true, "the frame's CAN identifier, e.g. 0x101");
  if (!present(n)) return std::nullopt;
  const std::uint32_t max = extended ? 0x1FFFFFFFu : 0x7FFu;
  try {
    std::size_t used = 0;
    const unsigned long v = std::stoul(n.Scalar(), &used, 0);
    if (used == n.Scalar().size() && v <= max) return static_cast<std::uint32_t>(v);
  } catch (const std::exception&) {}
  char lim[16];
  std::snprintf(lim, sizeof lim, "0x%X", max);
  r.diagnostics().add(n.Mark(), r.path_of("id"),
                      "= '" + n.Scalar() + "' is not allowed: an identifier 0 <= id <= " + lim +
                          (extended ? " (29-bit, extended_id)" : " (11-bit)"));
  return std::nullopt;
}

std::optional<CanSignal> read_can_signal(MapReader& parent, const std::string& key, const std::string& unit,
                                         int frame_bytes) {
  MapReader r(parent.diagnostics(), parent.child(key, true, "map with start_byte, size_bytes, scale, offset"),
              parent.path_of(key), parent.mark());
  CanSignal s;
  if (auto v = read_int(r, "start_byte", {"(byte)", 0, 63})) s.start_byte = *v;
  if (auto v = read_int(r, "size_bytes", {"(bytes)", 1, 4}, 2)) s.size_bytes = *v;
  if (auto v = read_bool(r, "signed", true)) s.is_signed = *v;
  if (auto v = r.choice("byte_order", {"little", "big"}, "little"))
    s.byte_order = *v == "little" ? ByteOrder::kLittle : ByteOrder::kBig;
  if (auto v = r.number("scale_" + unit + "_per_count", {unit, -1e6, 1e6}, std::nullopt)) s.scale = *v;
  if (s.scale == 0.0)
    r.diagnostics().add(r.mark(), r.path_of("scale_" + unit + "_per_count"), "= 0 would lose the signal");
  if (auto v = r.number("offset_" + unit, {unit, -1e6, 1e6}, 0.0)) s.offset = *v;
  r.finish();
  if (s.start_byte + s.size_bytes > frame_bytes)
    parent.diagnostics().add(r.mark(), parent.path_of(key),
                             "bytes " + std::to_string(s.start_byte) + ".." +
                                 std::to_string(s.start_byte + s.size_bytes - 1) +
                                 " do not fit in length_bytes = " + std::to_string(frame_bytes));
  return s;
}

CanFrameMapping read_can_frame(MapReader& top, const std::string& key, const std::string& unit, bool fd) {
  MapReader r(top.diagnostics(), top.child(key, true, "map with id, length_bytes, value"), top.path_of(key),
              top.mark());
  CanFrameMapping f;
  if (auto v = read_bool(r, "extended_id", false)) f.extended_id = *v;
  if (auto v = read_can_id(r, f.extended_id)) f.id = *v;
  if (auto v = read_int(r, "length_bytes",
                        {"(bytes)", 1.0, fd ? 64.0 : 8.0, false, false, fd ? "CAN FD" : "classic CAN"}, 8)) {
    const bool fd_len = *v <= 8 || *v == 12 || *v == 16 || *v == 20 || *v == 24 || *v == 32 || *v == 48 || *v == 64;
    if (!fd_len)
      r.diagnostics().add(r.mark(), r.path_of("length_bytes"),
                          "= " + std::to_string(*v) + " is not a CAN FD length: 0-8, 12, 16, 20, 24, 32, 48 or 64");
    else
      f.length_bytes = *v;
  }
  if (auto s = read_can_signal(r, "value", unit, f.length_bytes)) f.value = *s;
  const YAML::Node cn = r.child("counter", false, "");
  if (present(cn)) {
    MapReader cr(r.diagnostics(), cn, r.path_of("counter"), r.mark());
    CanCounter c;
    if (auto v = read_int(cr, "start_byte", {"(byte)", 0, 63})) c.start_byte = *v;
    if (auto v = read_int(cr, "size_bytes", {"(bytes)", 1, 4}, 1)) c.size_bytes = *v;
    cr.finish();
    if (c.start_byte + c.size_bytes > f.length_bytes)
      r.diagnostics().add(cn.Mark(), r.path_of("counter"),
                          "does not fit in length_bytes = " + std::to_string(f.length_bytes));
    const bool overlap =
        c.start_byte < f.value.start_byte + f.value.size_bytes && f.value.start_byte < c.start_byte + c.size_bytes;
    if (overlap) r.diagnostics().add(cn.Mark(), r.path_of("counter"), "overlaps the value's bytes");
    f.counter = c;
  }
  r.finish();
  return f;
}

std::optional<CanConfig> read_can(MapReader& top, std::optional<double> rate) {
  const YAML::Node node = top.child("can", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(top.diagnostics(), node, "can", top.mark());
  CanConfig c;
  c.interface = r.text("interface", c.interface).value_or(c.interface);
  if (auto v = read_bool(r, "fd", false)) c.fd = *v;
  if (auto v = r.number("bitrate_bps", {"bit/s", 10e3, 1e6}, c.bitrate_bps)) c.bitrate_bps = *v;
  if (c.fd) {
    if (auto v = r.number("data_bitrate_bps",
                          {"bit/s", 0.0, 12e6, false, false, "CAN FD data phase; 0 = no bit-rate switch"}, 0.0))
      c.data_bitrate_bps = *v;
  }
  c.sensor = read_can_frame(r, "sensor", "mps2", c.fd);
  c.command = read_can_frame(r, "command", "v", c.fd);
  if (c.sensor.id == c.command.id && c.sensor.extended_id == c.command.extended_id)
    r.diagnostics().add(r.mark(), "can.command.id", "is the sensor frame's identifier too: they must differ");
  if (auto v = r.number("bus_load_max", {"(fraction of bus time)", 0.0, 1.0, true, false}, c.bus_load_max))
    c.bus_load_max = *v;
  if (auto v = read_int(r, "lost_frames_fault", {"(frames per second)", 1, 1024}, c.lost_frames_fault))
    c.lost_frames_fault = *v;
  if (auto v = r.number("backoff_initial_s", {"s", 0.0, 10.0, true, false}, c.backoff_initial_s))
    c.backoff_initial_s = *v;
  if (auto v = r.number("backoff_max_s", {"s", 0.0, 600.0, true, false}, c.backoff_max_s)) c.backoff_max_s = *v;
  r.finish();
  if (rate) {
    const double load = can_bus_load(c, *rate);
    if (load > c.bus_load_max) {
      char msg[400];
      std::snprintf(
          msg, sizeof msg,
          "the bus cannot carry this loop: %.0f Hz x (%.1f us sensor + %.1f us command frame, worst-case "
          "stuffing) = %.0f %% of the bus at %.0f kbit/s%s, above can.bus_load_max = %.0f %%; the highest loop "
          "rate is %.0f Hz",
          *rate, 1e6 * can_frame_time_s(c.sensor, c.fd, c.bitrate_bps, c.data_bitrate_bps),
          1e6 * can_frame_time_s(c.command, c.fd, c.bitrate_bps, c.data_bitrate_bps), 100.0 * load, c.bitrate_bps / 1e3,
          c.fd && c.data_bitrate_bps > 0
              ? (" / " + std::to_string(static_cast<int>(c.data_bitrate_bps / 1e3)) + " kbit/s data").c_str()
              : "",
          100.0 * c.bus_load_max, std::floor(*rate * c.bus_load_max / load));
      r.diagnostics().add(r.mark(), "loop.rate_hz", msg);
    }
  }
  return c;
}

// Where a dotted key (section.field) stands in the document: the field, else its section, else the top.
SourceMark mark_of(const YAML::Node& root, const std::string& dotted) {
  const std::size_t dot = dotted.find('.');
  try {
    const YAML::Node section = root[dotted.substr(0, dot)];
    if (section && section.IsMap()) {
      if (const YAML::Node field = section[dotted.substr(dot + 1)]) return detail::to_mark(field.Mark());
      return detail::to_mark(section.Mark());
    }
  } catch (const YAML::Exception&) {}
  return detail::to_mark(root.Mark());
}

// Locations named outside the robot section must exist in it.
void check_location_refs(Diagnostics& d, const Config& c, const YAML::Node& root) {
  if (c.robot.frfs.empty()) return;
  const std::pair<const char*, int> refs[] = {
      {"actuator.location", c.actuator.location},
      {"sensor.location", c.sensor.location},
      {"disturbances.drive_vibration_location", c.disturbances.drive_vibration_location}};
  for (const auto& [key, id] : refs)
    if (!find_location(c.robot, id)) {
      std::string known;
      for (const auto& l : c.robot.locations) known += (known.empty() ? "" : ", ") + std::to_string(l.id);
      d.add(mark_of(root, key), key, "= " + std::to_string(id) + " is not a robot location (known: " + known + ")");
    }
}

}  // namespace

namespace {

// dds.joint_states against pose_schedule and Modbus: a name per joint, one source of the pose.
void check_joint_states(detail::Diagnostics& d, const Config& c) {
  const SourceMark here{};
  if (!c.dds || !c.dds->joint_states) return;
  const JointStatesConfig& j = *c.dds->joint_states;
  if (!c.pose_schedule) {
    d.add(here, "dds.joint_states", "is set without pose_schedule: the joint angles would select nothing");
    return;
  }
  if (!j.names.empty() && j.names.size() != c.pose_schedule->joints())
    d.add(here, "dds.joint_states.names",
          "has " + std::to_string(j.names.size()) + " names; pose_schedule has " +
              std::to_string(c.pose_schedule->joints()) + " joints: one name per joint, in order");
  if (c.modbus && c.modbus->robot.joints_register >= 0)
    d.add(here, "dds.joint_states",
          "and modbus.robot.joints_register = " + std::to_string(c.modbus->robot.joints_register) +
              " both give the pose: choose one source");
}

// dds.path_ahead against pose_schedule: a name per joint (its own or dds.joint_states').
void check_path_ahead(detail::Diagnostics& d, const Config& c) {
  const SourceMark here{};
  if (!c.dds || !c.dds->path_ahead) return;
  const PathAheadConfig& p = *c.dds->path_ahead;
  if (!c.pose_schedule) {
    d.add(here, "dds.path_ahead", "is set without pose_schedule: the advice has no robot model to check the poses on");
    return;
  }
  // (Names not given are dds.joint_states', filled in as the section is read.)
  if (p.names.empty())
    d.add(here, "dds.path_ahead",
          "needs names (pose_schedule's joints as the robot program names them) without dds.joint_states");
  else if (p.names.size() != c.pose_schedule->joints())
    d.add(here, "dds.path_ahead.names",
          "has " + std::to_string(p.names.size()) + " names; pose_schedule has " +
              std::to_string(c.pose_schedule->joints()) + " joints: one name per joint, in order");
}

// modbus.robot.joints_register against pose_schedule: one register per joint, clear of the others.
void check_joint_registers(detail::Diagnostics& d, const Config& c) {
  const SourceMark here{};  // located() gives it the key's line
  if (!c.modbus) return;
  const RobotRegisters& r = c.modbus->robot;
  if (r.joints_register < 0) return;
  if (!c.pose_schedule) {
    d.add(here, "modbus.robot.joints_register",
          "= " + std::to_string(r.joints_register) +
              " is set without pose_schedule: the joint angles would select nothing");
    return;
  }
  const int first = r.joints_register, last = first + static_cast<int>(c.pose_schedule->joints()) - 1;
  for (const auto& [key, reg] :
       {std::pair{"mounting_register", r.mounting_register}, std::pair{"spindle_rpm_register", r.spindle_rpm_register}})
    if (reg >= first && reg <= last)
      d.add(here, "modbus.robot.joints_register",
            "= " + std::to_string(first) + " covers registers " + std::to_string(first) + "-" + std::to_string(last) +
                " (one per joint), which holds modbus.robot." + key + " = " + std::to_string(reg) +
                ": they must differ");
  if (last > 65535)
    d.add(here, "modbus.robot.joints_register",
          "= " + std::to_string(first) + ": the joints' registers run past 65535");
}

}  // namespace

namespace detail {

std::optional<BlockConfig> read_chain_block(Diagnostics& d, const YAML::Node& node, const std::string& key,
                                            std::optional<double> rate_hz) {
  return read_block(d, node, key, rate_hz);
}

}  // namespace detail

Config parse_config(const std::string& yaml_text, const std::string& source_name) {
  Diagnostics d(source_name);
  const YAML::Node root = detail::load_top_map(d, yaml_text, "loop, actuator, amplifier, controller, robot");
  Config c;
  c.source = source_name;
  c.yaml_text = yaml_text;
  MapReader top(d, root, "", root.Mark());
  std::optional<double> rate;
  c.loop = read_loop(top, rate);
  c.actuator = read_actuator(top, rate);
  c.amplifier = read_amplifier(top);
  c.controller = read_controller(top, rate);
  c.robot = read_robot(top, rate);
  c.sensor = read_sensor(top, rate);
  c.plant = read_plant(top);
  c.disturbances = read_disturbances(top);
  c.analysis = read_analysis(top, rate);
  c.bench = read_bench(top);
  c.realtime = read_realtime(top);
  c.supervision = read_supervision(top);
  c.telemetry = read_telemetry(top);
  c.can = read_can(top, rate);
  detail::read_supervisory(top, c);
  c.commissioning = detail::read_commissioning(top);
  c.spindle = detail::read_spindle(top, c.source);
  c.pose_schedule = detail::read_pose_schedule(top, c.source);
  if (c.pose_schedule && !c.parameter_sets.empty())
    d.add(root.Mark(), "pose_schedule",
          "and parameter_sets select parameter sets both: a configuration schedules by pose or by mounting, not both");
  if (!c.hil.robot_model.empty()) {
    if (!c.pose_schedule)
      d.add(root.Mark(), "hil.robot_model",
            "is set without pose_schedule: the emulator moves a robot model along a pose trajectory only");
    else if (!c.hil.robot_model_resolved.empty() && !c.pose_schedule->model_resolved.empty())
      try {
        const std::size_t n = load_robot_model(c.hil.robot_model_resolved).joints.size();
        if (n != c.pose_schedule->joints())
          d.add(root.Mark(), "hil.robot_model",
                "has " + std::to_string(n) + " joints; pose_schedule.model has " +
                    std::to_string(c.pose_schedule->joints()) +
                    ": the emulated robot and the configured model are read with the same joint angles");
      } catch (const ConfigError&) {
        // reported where hil.robot_model was read
      }
  }
  if (const auto& s = c.controller.speed_schedule) {
    if (c.pose_schedule)
      d.add(root.Mark(), "controller.speed_schedule",
            "and pose_schedule both choose the controller: a configuration schedules by spindle speed or by pose, not "
            "both");
    if (!s->controllers.empty() && !c.parameter_sets.empty())
      d.add(root.Mark(), "controller.speed_schedule.controllers",
            "and parameter_sets both choose the controller: a configuration schedules by spindle speed or by mounting, "
            "not both (a schedule of K alone may stand beside parameter_sets)");
    if (!s->controllers.empty() && std::none_of(c.controller.chain.begin(), c.controller.chain.end(),
                                                [](const BlockConfig& b) { return b.kind == BlockKind::kCompensator; }))
      d.add(root.Mark(), "controller.speed_schedule.controllers",
            "each replace the chain's compensator block, and controller.chain has none");
    if (!s->bands.empty() && s->bands.back().rpm_max > c.spindle.rpm_max)
      d.add(root.Mark(), "controller.speed_schedule.bands",
            "reach " + format_number(s->bands.back().rpm_max) +
                " rpm, above spindle.rpm_max = " + format_number(c.spindle.rpm_max) + " rpm");
  }
  check_joint_registers(d, c);
  check_joint_states(d, c);
  check_path_ahead(d, c);
  top.finish();
  check_location_refs(d, c, root);
  if (!d.problems().empty()) throw ConfigError(located(d.problems(), yaml_text));
  return c;
}

Config load_config_file(const std::string& path) { return parse_config(detail::read_config_text(path), path); }

const LocationConfig* find_location(const RobotConfig& robot, int id) {
  for (const auto& l : robot.locations)
    if (l.id == id) return &l;
  return nullptr;
}

rt::SupervisorSettings supervisor_settings(const Config& cfg, bool analysis_stable, double max_stable_gain_ns_per_m,
                                           double delay_margin_s) {
  rt::SupervisorSettings s;
  s.limits = cfg.supervision;
  s.fs_hz = cfg.loop.rate_hz;
  s.sample_limit_mps2 = cfg.supervision.sample_limit_mps2 > 0.0 ? cfg.supervision.sample_limit_mps2
                                                                : cfg.sensor.range_g * kStandardGravityMps2;
  s.fade_s = cfg.controller.gain_ramp_s;
  s.analysis_stable = analysis_stable;
  s.max_stable_gain_ns_per_m = max_stable_gain_ns_per_m;
  s.delay_margin_s = delay_margin_s;
  s.command_limit_v = cfg.amplifier.voltage_limit_v;
  return s;
}

}  // namespace robodamp::config
