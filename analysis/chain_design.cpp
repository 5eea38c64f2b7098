#include "modal/receptance.hpp"
#include "analysis/chain_design.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <sstream>

namespace robodamp::analysis {

using config::BlockKind;
using control::ControllerParams;
using filters::Complex;
using filters::TransferFunction;

namespace {

std::string format_hz(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

TransferFunction analog_of(const config::BlockConfig& b, const config::ActuatorConfig& act) {
  switch (b.kind) {
    case BlockKind::kLowpass2:
      return filters::lowpass2(b.cutoff_hz, b.damping_ratio);
    case BlockKind::kHighpass2:
      return filters::highpass2(b.cutoff_hz, b.damping_ratio);
    case BlockKind::kNotch:
      return filters::notch(b.center_hz, b.bandwidth_hz);
    case BlockKind::kIntegrator:
      return filters::integrator(b.leak_hz);
    case BlockKind::kCompensator:
      switch (b.model) {
        case config::CompensatorModel::kC1:
          return filters::compensator_c1(act.natural_freq_hz, act.damping_ratio, b.corner_hz, b.corner_damping_ratio);
        case config::CompensatorModel::kC2:
          return filters::compensator_c2();
        case config::CompensatorModel::kC3:
          return filters::compensator_c3();
        case config::CompensatorModel::kRational:
          return {filters::Polynomial::from_descending(b.numerator),
                  filters::Polynomial::from_descending(b.denominator)};
      }
  }
  return {};
}

using Problems = std::vector<config::Problem>;

// The frequency compensators are pre-warped at: match_freq_hz, else the dominant robot mode.
void choose_match_frequency(const config::Config& cfg, ChainDesign& d, Problems& problems) {
  const auto& chain = cfg.controller.chain;
  if (cfg.controller.match_freq_hz) {
    d.match_freq_hz = *cfg.controller.match_freq_hz;
  } else if (auto dom = modal::dominant_mode_hz(cfg.robot, cfg.actuator.location)) {
    d.match_freq_hz = *dom;
  } else {
    const bool needs = std::any_of(chain.begin(), chain.end(),
                                   [](const auto& b) { return b.kind == BlockKind::kCompensator && !b.prewarp_hz; });
    if (needs)
      problems.push_back({cfg.source,
                          {},
                          "controller.match_freq_hz",
                          "missing: compensators are pre-warped at the dominant robot mode, and there is no robot "
                          "modal data; set match_freq_hz (Hz, below Nyquist)"});
  }
}

// Each block of Eq. 8 in chain order, analog, with its pre-warp frequency; the integrator takes its
// high-pass partner's (partner < 0: none).
void analog_blocks(const config::Config& cfg, std::ptrdiff_t partner, ChainDesign& d) {
  const auto& chain = cfg.controller.chain;
  for (const auto& b : chain) {
    ChainBlock cb{b.name, b.kind, analog_of(b, cfg.actuator), 0.0, 0};
    switch (b.kind) {
      case BlockKind::kLowpass2:
      case BlockKind::kHighpass2:
        cb.prewarp_hz = b.cutoff_hz;
        break;
      case BlockKind::kNotch:
        cb.prewarp_hz = b.center_hz;
        break;
      case BlockKind::kIntegrator:
        cb.prewarp_hz = partner >= 0 ? chain[static_cast<std::size_t>(partner)].prewarp_hz.value_or(
                                           chain[static_cast<std::size_t>(partner)].cutoff_hz)
                                     : d.match_freq_hz;
        break;
      case BlockKind::kCompensator:
        cb.prewarp_hz = d.match_freq_hz;
        break;
    }
    if (b.prewarp_hz) cb.prewarp_hz = *b.prewarp_hz;
    d.blocks.push_back(std::move(cb));
  }
}

// The digital groups in configured order (pre-warped bilinear, second-order sections); the
// integrator/high-pass pair is one group where the integrator is (1/s cancels against s^2 exactly).
void realise_groups(const config::Config& cfg, std::ptrdiff_t integrator, std::ptrdiff_t partner, ChainDesign& d,
                    Problems& problems) {
  const auto& chain = cfg.controller.chain;
  const double fs = cfg.loop.rate_hz;
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (static_cast<std::ptrdiff_t>(i) == partner) continue;
    RealisedGroup g;
    g.label = d.blocks[i].name;
    g.blocks = {i};
    g.analog = d.blocks[i].analog;
    double prewarp = d.blocks[i].prewarp_hz;
    if (static_cast<std::ptrdiff_t>(i) == integrator && partner >= 0) {
      const auto p = static_cast<std::size_t>(partner);
      g.label += "*" + d.blocks[p].name;
      g.blocks.push_back(p);
      g.analog = d.blocks[i].analog * d.blocks[p].analog;
      prewarp = d.blocks[p].prewarp_hz;
    }
    try {
      g.digital = filters::bilinear_sos(g.analog, fs, prewarp);
    } catch (const filters::DesignError& e) {
      problems.push_back({cfg.source, chain[i].mark, chain[i].key,
                          std::string(config::to_string(chain[i].kind)) + " '" + chain[i].name +
                              "' cannot be realised at loop.rate_hz = " + format_hz(fs) + " Hz: " + e.what()});
      continue;
    }
    for (std::size_t k : g.blocks) d.blocks[k].group = d.groups.size();
    d.groups.push_back(std::move(g));
  }
}

// The controller's parameters from the sections and the configuration's limits and notches.
void fill_params(const config::Config& cfg, const std::vector<filters::BiquadCoefficients>& sections, double gain,
                 ControllerParams& p) {
  const double fs = cfg.loop.rate_hz;
  p.fs_hz = fs;
  p.sections = filters::SosCoefficients::from(sections);
  p.sections_gain = gain;
  p.gain_ns_per_m = cfg.controller.gain_ns_per_m;
  p.gain_ramp_s = cfg.controller.gain_ramp_s;
  // Slowest pole radius of any section: its transient falls to 1e-3 in ln(1e-3)/ln(r) samples.
  double r_max = 0.0;
  for (const auto& s : sections) r_max = std::max(r_max, filters::pole_radius(s));
  p.settle_s = r_max > 0.0 ? std::log(1e-3) / std::log(r_max) / fs : 0.0;
  p.polarity = cfg.controller.polarity;
  p.actuator_constant_n_per_v = cfg.actuator.constant_n_per_v;
  p.force_limit_n = cfg.actuator.force_limit_n;
  p.voltage_limit_v = cfg.amplifier.voltage_limit_v;
  p.slew_rate_v_per_s = cfg.amplifier.slew_rate_v_per_s;
  if (const auto& n = cfg.controller.harmonic_notch) {
    p.harmonic_notch.enabled = true;
    p.harmonic_notch.harmonics = n->harmonics;
    p.harmonic_notch.bandwidth_hz = n->bandwidth_hz;
    p.harmonic_notch.depth_db = n->depth_db;
    p.harmonic_notch.slew_fraction = n->slew_fraction;
    p.harmonic_notch.min_hz = n->min_hz;
    p.harmonic_notch.fade_s = n->fade_s;
    p.harmonic_notch.update_hz = n->update_hz;
  }
  p.spindle_teeth = cfg.spindle.teeth;
  p.spindle_rpm_max = cfg.spindle.rpm_max;
  static_assert(ControllerParams::kMaxSpeedBands == config::kMaxSpeedBands);
  p.speed_band_count = 0;
  if (const auto& s = cfg.controller.speed_schedule)
    for (const auto& b : s->bands) {
      if (p.speed_band_count == ControllerParams::kMaxSpeedBands) break;  // the configuration refuses more
      // The band's controller is its parameter set: 0 this configuration's, i the schedule's controllers[i - 1]
      // (the cell adds them in that order, right after set 0).
      p.speed_bands[p.speed_band_count++] = {b.rpm_min, b.rpm_max, b.gain_ns_per_m,
                                             static_cast<std::size_t>(b.controller)};
    }
}

}  // namespace

ChainDesign design_chain(const config::Config& cfg) {
  const auto& chain = cfg.controller.chain;
  Problems problems;
  ChainDesign d;
  d.source = cfg.source;
  choose_match_frequency(cfg, d, problems);
  // The high-pass the integrator is realised with (see RealisedGroup).
  std::ptrdiff_t integrator = -1, partner = -1;
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (chain[i].kind == BlockKind::kIntegrator && chain[i].leak_hz == 0.0) integrator = static_cast<std::ptrdiff_t>(i);
    if (chain[i].kind == BlockKind::kHighpass2 && partner < 0) partner = static_cast<std::ptrdiff_t>(i);
  }
  if (integrator < 0) partner = -1;
  analog_blocks(cfg, partner, d);
  realise_groups(cfg, integrator, partner, d, problems);
  std::vector<filters::BiquadCoefficients> sections;
  double gain = 1.0;
  for (const auto& g : d.groups) {
    sections.insert(sections.end(), g.digital.sections.begin(), g.digital.sections.end());
    gain *= g.digital.gain;
  }
  if (problems.empty() && sections.size() > filters::kMaxSections)
    problems.push_back({cfg.source,
                        {},
                        "controller.chain",
                        "needs " + std::to_string(sections.size()) + " second-order sections, at most " +
                            std::to_string(filters::kMaxSections) + " are supported"});
  if (!problems.empty()) throw config::ConfigError(config::located(problems, cfg.yaml_text));
  fill_params(cfg, sections, gain, d.params);
  return d;
}

Complex ChainDesign::filters_analog(double f_hz) const {
  Complex h(1.0);
  for (const auto& b : blocks) h *= b.analog.at_hz(f_hz);
  return h;
}

Complex ChainDesign::filters_digital(double f_hz) const {
  return filters::digital_response(
      std::span<const filters::BiquadCoefficients>(params.sections.sections.data(), params.sections.count),
      params.sections_gain, f_hz, params.fs_hz);
}

Complex ChainDesign::chain_analog(double f_hz) const {
  return filters_analog(f_hz) * (params.polarity * params.gain_ns_per_m / params.actuator_constant_n_per_v);
}

Complex ChainDesign::chain_digital(double f_hz) const {
  return filters_digital(f_hz) * (params.polarity * params.gain_ns_per_m / params.actuator_constant_n_per_v);
}

Complex ChainDesign::block_digital(std::size_t i, double f_hz) const {
  const RealisedGroup& g = groups.at(blocks.at(i).group);
  if (g.blocks.size() == 1) return filters::digital_response(g.digital.sections, g.digital.gain, f_hz, params.fs_hz);
  return filters::bilinear_response(blocks[i].analog, f_hz, params.fs_hz, g.digital.prewarp_hz);
}

}  // namespace robodamp::analysis
