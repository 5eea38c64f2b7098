// The file robodamp schedule writes: the configuration's text with controller.speed_schedule in block style
// (tune/speed_schedule.hpp, scheduled_config_text).
#include <sstream>
#include <string>

#include "tune/speed_schedule.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::tune {

namespace {

// A band's controller as the schedule writes it: the compensator block and polarity that replace the chain's.
std::string controller_text(const config::SpeedControllerConfig& c) {
  const config::BlockConfig& b = c.compensator.front();
  std::ostringstream o;
  o << "{polarity: " << (c.polarity > 0 ? "+1" : "-1");
  if (c.match_freq_hz) o << ", match_freq_hz: " << exact(*c.match_freq_hz);
  o << ", compensator: {kind: compensator, model: " << config::to_string(b.model);
  if (b.model == config::CompensatorModel::kC1)
    o << ", corner_hz: " << exact(b.corner_hz) << ", corner_damping_ratio: " << exact(b.corner_damping_ratio);
  auto list = [&](const char* key, const std::vector<double>& v) {
    o << ", " << key << ": [";
    for (std::size_t i = 0; i < v.size(); ++i) o << (i ? ", " : "") << exact(v[i]);
    o << "]";
  };
  if (b.model == config::CompensatorModel::kRational)
    list("numerator", b.numerator), list("denominator", b.denominator);
  if (b.prewarp_hz) o << ", prewarp_hz: " << exact(*b.prewarp_hz);
  o << "}}";
  return o.str();
}

// The schedule in block style, a band per line, at the indentation of the key it replaces.
std::string schedule_block(const std::string& indent, const SpeedSchedule& s) {
  std::ostringstream o;
  o << indent << "speed_schedule:   # robodamp schedule: the controller and K by spindle speed (docs/tuning.md)\n";
  if (s.controllers.size() > 1) {
    o << indent << "  controllers:    # a band's controller i >= 1: this chain with controllers[i - 1]'s compensator\n";
    for (std::size_t i = 1; i < s.controllers.size(); ++i)
      o << indent << "    - " << controller_text(*s.controllers[i].entry) << "   # from " << s.controllers[i].file
        << "\n";
  }
  o << indent << "  bands:\n";
  for (const auto& b : s.bands)
    o << indent << "    - {rpm_min: " << exact(b.rpm_min) << ", rpm_max: " << exact(b.rpm_max)
      << ", controller: " << b.controller << ", gain_ns_per_m: " << exact(b.gain_ns_per_m)
      << (b.depth_limit_mm ? ", depth_limit_mm: " + exact(*b.depth_limit_mm) : std::string()) << "}"
      << (b.depth_limit_mm ? "   # the cut in time holds less than the accurate method's limit" : "") << "\n";
  return o.str();
}

}  // namespace

// So the new schedule is written in the block form again, not as an edit in place.
std::string without_schedule_block(const std::string& text) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  std::size_t key_indent = std::string::npos;
  std::string blanks;  // blank lines inside the block, kept if the block ends after them
  while (std::getline(in, line)) {
    const std::size_t indent = line.find_first_not_of(' ');
    if (key_indent != std::string::npos) {
      if (indent == std::string::npos) {
        blanks += line + '\n';
        continue;
      }
      if (indent > key_indent || line[indent] == '#') {
        blanks.clear();
        continue;
      }
      key_indent = std::string::npos;
      out << blanks;
      blanks.clear();
    }
    if (indent != std::string::npos && line.compare(indent, 15, "speed_schedule:") == 0) {
      key_indent = indent;
      continue;
    }
    out << line << '\n';
  }
  return out.str();
}

std::string without_schedule(const std::string& text) {
  std::string out = without_schedule_block(text);
  if (YAML::Node doc = YAML::Load(out); doc["controller"].IsMap() && doc["controller"]["speed_schedule"]) {
    doc["controller"].remove("speed_schedule");  // not in block style: the document emitted again, without it
    YAML::Emitter e;
    e << doc;
    return std::string(e.c_str()) + "\n";
  }
  if (out.rfind("# robodamp schedule wrote", 0) != 0) return out;
  const std::size_t end = out.find("# Everything else is ");
  if (end == std::string::npos) return out;
  std::size_t next = out.find('\n', end);
  next = next == std::string::npos ? out.size() : next + 1;
  if (out.compare(next, 2, "#\n") == 0) next += 2;
  return out.substr(next);
}

config::EditedYaml scheduled_config_text(const config::Config& cell_in, const SpeedSchedule& s) {
  config::Config cell = cell_in;
  if (cell.controller.speed_schedule) cell.yaml_text = without_schedule_block(cell.yaml_text);
  YAML::Node schedule(YAML::NodeType::Map);
  YAML::Node controllers(YAML::NodeType::Sequence);
  for (std::size_t i = 1; i < s.controllers.size(); ++i)
    controllers.push_back(YAML::Load(controller_text(*s.controllers[i].entry)));
  if (controllers.size() > 0) schedule["controllers"] = controllers;
  YAML::Node bands(YAML::NodeType::Sequence);
  for (const auto& b : s.bands) {
    YAML::Node band(YAML::NodeType::Map);
    band.SetStyle(YAML::EmitterStyle::Flow);
    band["rpm_min"] = exact(b.rpm_min);
    band["rpm_max"] = exact(b.rpm_max);
    band["controller"] = b.controller;
    band["gain_ns_per_m"] = exact(b.gain_ns_per_m);
    if (b.depth_limit_mm) band["depth_limit_mm"] = exact(*b.depth_limit_mm);
    bands.push_back(band);
  }
  schedule["bands"] = bands;
  config::EditedYaml out = config::edit_yaml(cell.yaml_text, {{{"controller", "speed_schedule"}, schedule}});
  // The edit writes a collection as one flow line; a person reads the block form, which reads back the same.
  const std::size_t at = out.text.find("speed_schedule: {");
  if (!out.comments_kept || at == std::string::npos) return out;
  const std::size_t line = out.text.rfind('\n', at) + 1;
  const std::size_t end = out.text.find('\n', at);
  std::string text = out.text.substr(0, line) + schedule_block(out.text.substr(line, at - line), s) +
                     (end == std::string::npos ? "" : out.text.substr(end + 1));
  const YAML::Node back = config::yaml_at(YAML::Load(text), {"controller", "speed_schedule", "bands"});
  if (!back.IsSequence() || back.size() != s.bands.size()) return out;
  out.text = std::move(text);
  return out;
}

}  // namespace robodamp::tune
