#include "config/config.hpp"

#include <cmath>
#include <complex>
#include <fstream>
#include <set>
#include <sstream>

#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::Diagnostics;
using detail::format_number;
using detail::MapReader;
using detail::Range;

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

ConfigError::ConfigError(std::vector<Problem> problems)
    : std::runtime_error(summarise(problems)), problems_(std::move(problems)) {}

const char* to_string(BlockKind kind) {
  switch (kind) {
    case BlockKind::kLowpass2: return "lowpass2";
    case BlockKind::kHighpass2: return "highpass2";
    case BlockKind::kNotch: return "notch";
    case BlockKind::kIntegrator: return "integrator";
    case BlockKind::kCompensator: return "compensator";
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
    case CompensatorModel::kC1: return "c1";
    case CompensatorModel::kC2: return "c2";
    case CompensatorModel::kC3: return "c3";
    case CompensatorModel::kRational: return "rational";
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
  return {"Hz", 0.0, nyq, true, true,
          rate_hz ? "below Nyquist, loop.rate_hz = " + format_number(*rate_hz) + " Hz" : "below Nyquist"};
}

const Range kDamping{"(dimensionless)", 0.0, 10.0, true, false};

LoopConfig read_loop(MapReader& top, std::optional<double>& rate) {
  MapReader r(top.diagnostics(), top.child("loop", true, "map with rate_hz"), "loop", top.mark());
  LoopConfig c;
  rate = r.number("rate_hz", {"Hz", kMinRateHz, kMaxRateHz});
  if (rate) c.rate_hz = *rate;
  r.finish();
  return c;
}

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
          if (chain[i].IsMap() && chain[i]["kind"].IsScalar())
            if (auto k = block_kind_from(chain[i]["kind"].Scalar())) ++counts[static_cast<int>(*k)];
          continue;
        }
        const int n = ++counts[static_cast<int>(b->kind)];
        if (b->name.empty()) b->name = std::string(to_string(b->kind)) + (n > 1 ? "_" + std::to_string(n) : "");
        if (!names.insert(b->name).second) d.add(chain[i].Mark(), key + ".name", "= '" + b->name + "' is used twice");
        c.chain.push_back(*b);
      }
      const YAML::Mark m = chain.Mark();
      if (counts[static_cast<int>(BlockKind::kIntegrator)] != 1)
        d.add(m, "controller.chain", "needs exactly one integrator block (DVF feeds back velocity, Eq. 8), found " +
                                         std::to_string(counts[static_cast<int>(BlockKind::kIntegrator)]));
      for (const auto& b : c.chain)
        if (b.kind == BlockKind::kIntegrator && b.leak_hz == 0.0 && counts[static_cast<int>(BlockKind::kHighpass2)] == 0)
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
  const YAML::Node frfs = r.child("frfs", true, "list of FRFs, each a sum of modes (Eq. 1)");
  if (frfs.IsDefined() && !frfs.IsNull()) {
    if (!frfs.IsSequence()) d.add(frfs.Mark(), "robot.frfs", "must be a list");
    std::set<std::string> names;
    for (std::size_t i = 0; frfs.IsSequence() && i < frfs.size(); ++i) {
      const std::string key = "robot.frfs[" + std::to_string(i) + "]";
      MapReader fr(d, frfs[i], key, frfs.Mark());
      FrfConfig f;
      f.name = fr.text("name", std::nullopt).value_or("");
      if (!names.insert(f.name).second) d.add(frfs[i].Mark(), key + ".name", "= '" + f.name + "' is used twice");
      if (auto v = fr.number("response_location", {"(location index)", 1, 16})) f.response_location = static_cast<int>(*v);
      if (auto v = fr.number("excitation_location", {"(location index)", 1, 16})) f.excitation_location = static_cast<int>(*v);
      const YAML::Node modes = fr.child("modes", true, "list of modes");
      if (modes.IsDefined() && (!modes.IsSequence() || modes.size() == 0))
        d.add(modes.Mark(), key + ".modes", "must be a non-empty list of modes");
      for (std::size_t k = 0; modes.IsSequence() && k < modes.size(); ++k) {
        MapReader mr(d, modes[k], key + ".modes[" + std::to_string(k) + "]", modes.Mark());
        ModeConfig m;
        if (auto v = mr.number("natural_freq_hz", below_nyquist(rate))) m.natural_freq_hz = *v;
        if (auto v = mr.number("damping_ratio", {"(dimensionless)", 0.0, 1.0, true, true})) m.damping_ratio = *v;
        if (auto v = mr.number("residue_re_m_per_n", {"m/N", -1.0, 1.0})) m.residue_re_m_per_n = *v;
        if (auto v = mr.number("residue_im_m_per_n", {"m/N", -1.0, 1.0})) m.residue_im_m_per_n = *v;
        mr.finish();
        f.modes.push_back(m);
      }
      fr.finish();
      robot.frfs.push_back(std::move(f));
    }
  }
  r.finish();
  return robot;
}

}  // namespace

Config parse_config(const std::string& yaml_text, const std::string& source_name) {
  Diagnostics d(source_name);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    d.add(e.mark, "(yaml)", "syntax error: " + e.msg);
    throw ConfigError(d.problems());
  }
  Config c;
  c.source = source_name;
  if (!root.IsMap()) {
    d.add(root.Mark(), "(top level)", "expected a map with loop, actuator, amplifier, controller, robot");
    throw ConfigError(d.problems());
  }
  MapReader top(d, root, "", root.Mark());
  std::optional<double> rate;
  c.loop = read_loop(top, rate);
  c.actuator = read_actuator(top, rate);
  c.amplifier = read_amplifier(top);
  c.controller = read_controller(top, rate);
  c.robot = read_robot(top, rate);
  top.finish();
  if (!d.problems().empty()) throw ConfigError(d.problems());
  return c;
}

Config load_config_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError({Problem{path, {}, "(file)", "cannot be opened for reading"}});
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_config(ss.str(), path);
}

std::optional<double> dominant_mode_hz(const RobotConfig& robot) {
  const FrfConfig* best_frf = nullptr;
  for (const auto& f : robot.frfs)
    if (f.response_location == 2 && f.excitation_location == 2) best_frf = &f;
  std::optional<double> best_hz;
  double best_peak = -1.0;
  for (const auto& f : robot.frfs) {
    if (best_frf != nullptr && &f != best_frf) continue;
    for (const auto& probe : f.modes) {
      // |H(j wn)| of the whole FRF at each mode's frequency (Eq. 1), so close modes count together.
      const double w = 2.0 * M_PI * probe.natural_freq_hz;
      std::complex<double> h(0.0);
      for (const auto& m : f.modes) {
        const double wn = 2.0 * M_PI * m.natural_freq_hz;
        const double wd = wn * std::sqrt(1.0 - m.damping_ratio * m.damping_ratio);
        const double a = 2.0 * (m.damping_ratio * wn * m.residue_re_m_per_n - wd * m.residue_im_m_per_n);
        const double b = 2.0 * m.residue_re_m_per_n;
        const std::complex<double> s(0.0, w);
        h += (a + b * s) / (s * s + 2.0 * m.damping_ratio * wn * s + wn * wn);
      }
      if (std::abs(h) > best_peak) best_peak = std::abs(h), best_hz = probe.natural_freq_hz;
    }
  }
  return best_hz;
}

}  // namespace robodamp::config
