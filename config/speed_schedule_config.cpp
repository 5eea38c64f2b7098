#include "config/speed_schedule_config.hpp"

#include <cmath>
#include <string>

#include "config/config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

std::optional<std::size_t> speed_band_of(const std::vector<SpeedBandConfig>& bands, double rpm) {
  for (std::size_t i = 0; i < bands.size(); ++i)
    if (rpm >= bands[i].rpm_min && (rpm < bands[i].rpm_max || (i + 1 == bands.size() && rpm == bands[i].rpm_max)))
      return i;
  return std::nullopt;  // NaN too
}

double scheduled_gain_ns_per_m(const Config& set_cfg, std::size_t set, double rpm) {
  const auto& s = set_cfg.controller.speed_schedule;
  if (!s) return set_cfg.controller.gain_ns_per_m;
  const auto b = speed_band_of(s->bands, rpm);
  if (!b) return set_cfg.controller.gain_ns_per_m;
  const SpeedBandConfig& band = s->bands[*b];
  return s->controllers.empty() || static_cast<std::size_t>(band.controller) == set ? band.gain_ns_per_m : 0.0;
}

std::size_t scheduled_set(const Config& set_cfg, std::size_t set, double rpm) {
  const auto& s = set_cfg.controller.speed_schedule;
  if (!s || s->controllers.empty()) return set;
  const auto b = speed_band_of(s->bands, rpm);
  return b ? static_cast<std::size_t>(s->bands[*b].controller) : 0;
}

std::optional<double> scheduled_depth_limit_mm(const Config& set_cfg, std::size_t set, double rpm) {
  const auto& s = set_cfg.controller.speed_schedule;
  if (!s) return std::nullopt;
  const auto b = speed_band_of(s->bands, rpm);
  if (!b || scheduled_gain_ns_per_m(set_cfg, set, rpm) <= 0.0) return std::nullopt;
  return s->bands[*b].depth_limit_mm;
}

Config with_speed_controller(const Config& cell, const SpeedControllerConfig& c) {
  Config out = cell;
  for (BlockConfig& b : out.controller.chain) {
    if (b.kind != BlockKind::kCompensator) continue;
    const std::string name = b.name, key = b.key;
    const SourceMark mark = b.mark;
    b = c.compensator.front();
    b.name = name, b.key = key, b.mark = mark;
    break;
  }
  out.controller.polarity = c.polarity;
  if (c.match_freq_hz) out.controller.match_freq_hz = c.match_freq_hz;
  return out;
}

Config speed_controller_config(const Config& cell, std::size_t i) {
  Config c = with_speed_controller(cell, cell.controller.speed_schedule->controllers.at(i - 1));
  c.controller.gain_ns_per_m = 0.0;
  return c;
}

SpeedControllerConfig speed_controller_of(const Config& other) {
  SpeedControllerConfig c;
  for (const BlockConfig& b : other.controller.chain)
    if (b.kind == BlockKind::kCompensator) c.compensator.assign(1, b);
  if (c.compensator.empty())
    throw ConfigError({{other.source, {}, "controller.chain", "has no compensator block for a speed band to run"}});
  c.polarity = other.controller.polarity;
  c.match_freq_hz = other.controller.match_freq_hz;
  return c;
}

namespace detail {

namespace {

std::optional<SpeedControllerConfig> read_controller_entry(Diagnostics& d, const YAML::Node& item,
                                                           const std::string& key, std::optional<double> rate_hz) {
  MapReader r(d, item, key, item.Mark());
  SpeedControllerConfig c;
  const std::size_t before = d.problems().size();
  if (auto p = read_sign(r, "polarity", 1)) c.polarity = *p;
  if (auto v =
          r.number("match_freq_hz", {"Hz", 0.0, rate_hz ? 0.5 * *rate_hz : 1e6, true, true, "below Nyquist"}, -1.0);
      v && *v > 0.0)
    c.match_freq_hz = *v;
  const YAML::Node block =
      r.child("compensator", true, "the block that replaces the chain's compensator (kind: compensator)");
  r.finish();
  if (present(block)) {
    auto b = read_chain_block(d, block, key + ".compensator", rate_hz);
    if (b && b->kind != BlockKind::kCompensator)
      d.add(block.Mark(), key + ".compensator.kind",
            "= '" + std::string(to_string(b->kind)) + "': it must be a compensator");
    else if (b)
      c.compensator.assign(1, *b);
  }
  if (d.problems().size() != before || c.compensator.empty()) return std::nullopt;
  return c;
}

void read_controllers(MapReader& r, SpeedScheduleConfig& s, std::optional<double> rate_hz) {
  Diagnostics& d = r.diagnostics();
  const YAML::Node node = r.child("controllers", false, "");
  if (!present(node)) return;
  if (!node.IsSequence()) {
    d.add(node.Mark(), "controller.speed_schedule.controllers",
          "must be a list of {polarity, compensator: {kind: compensator, ...}}");
    return;
  }
  if (node.size() > kMaxSpeedControllers - 1)
    d.add(node.Mark(), "controller.speed_schedule.controllers",
          "has " + std::to_string(node.size()) + " controllers: allowed at most " +
              std::to_string(kMaxSpeedControllers - 1));
  for (std::size_t i = 0; i < node.size(); ++i) {
    auto c =
        read_controller_entry(d, node[i], "controller.speed_schedule.controllers[" + std::to_string(i) + "]", rate_hz);
    s.controllers.push_back(c.value_or(SpeedControllerConfig{}));  // keeps the numbering of the bands' references
  }
}

std::optional<SpeedBandConfig> read_band(Diagnostics& d, const YAML::Node& item, const YAML::Mark& list_mark,
                                         std::size_t i, std::size_t controllers) {
  const std::string key = "controller.speed_schedule.bands[" + std::to_string(i) + "]";
  MapReader r(d, item, key, list_mark);
  const auto lo = r.number("rpm_min", {"rpm", 0.0, 200000.0});
  const auto hi = r.number("rpm_max", {"rpm", 0.0, 200000.0, true});
  const auto k = r.number("gain_ns_per_m", {"N s/m", 0.0, 1e5});
  const auto c = read_int(
      r, "controller", {"(0 = this configuration's, i = controllers[i - 1])", 0, static_cast<double>(controllers)}, 0);
  const bool capped = present(r.child("depth_limit_mm", false, ""));
  const std::optional<double> cap = capped ? r.number("depth_limit_mm", {"mm", 0.0, 1000.0, true}) : std::nullopt;
  r.finish();
  if (!lo || !hi || !k || !c || (capped && !cap)) return std::nullopt;
  if (!(*hi > *lo)) {
    d.add(item.Mark(), key + ".rpm_max",
          "= " + format_number(*hi) + " rpm must exceed rpm_min = " + format_number(*lo) + " rpm");
    return std::nullopt;
  }
  return SpeedBandConfig{*lo, *hi, *c, *k, cap};
}

}  // namespace

std::optional<SpeedScheduleConfig> read_speed_schedule(MapReader& controller, std::optional<double> rate_hz) {
  const YAML::Node node = controller.child("speed_schedule", false, "");
  if (!present(node)) return std::nullopt;
  Diagnostics& d = controller.diagnostics();
  MapReader r(d, node, "controller.speed_schedule", controller.mark());
  SpeedScheduleConfig s;
  read_controllers(r, s, rate_hz);
  const YAML::Node bands = r.child("bands", true, "list of speed bands {rpm_min, rpm_max, controller, gain_ns_per_m}");
  r.finish();
  if (!present(bands)) return s;
  if (!bands.IsSequence() || bands.size() == 0) {
    d.add(bands.Mark(), "controller.speed_schedule.bands",
          "must be a non-empty list of speed bands {rpm_min, rpm_max, controller, gain_ns_per_m}");
    return s;
  }
  if (bands.size() > kMaxSpeedBands)
    d.add(bands.Mark(), "controller.speed_schedule.bands",
          "has " + std::to_string(bands.size()) + " bands: allowed at most " + std::to_string(kMaxSpeedBands));
  for (std::size_t i = 0; i < bands.size(); ++i) {
    const auto b = read_band(d, bands[i], bands.Mark(), i, s.controllers.size());
    if (!b) continue;
    if (!s.bands.empty() && b->rpm_min < s.bands.back().rpm_max)
      d.add(bands[i].Mark(), "controller.speed_schedule.bands[" + std::to_string(i) + "].rpm_min",
            "= " + format_number(b->rpm_min) + " rpm overlaps the band before it (to " +
                format_number(s.bands.back().rpm_max) + " rpm): bands ascend and do not overlap");
    s.bands.push_back(*b);
  }
  return s;
}

}  // namespace detail

}  // namespace robodamp::config
