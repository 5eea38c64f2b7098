#include "tune/tuned_file.hpp"

#include <charconv>
#include <string>

#include "tune/speed_schedule.hpp"

namespace robodamp::tune {

std::string exact(double x) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}

// The configuration's own text with the compensator, the gain and the polarity set, as data
// (config/yaml_edit.hpp): any YAML style; comments kept where the splice is exact.
config::EditedYaml tuned_config_text(const config::Config& base, const Candidate& c) {
  const config::Config tuned = with_candidate(base, c);
  std::size_t index = 0;
  for (std::size_t i = 0; i < tuned.controller.chain.size(); ++i)
    if (tuned.controller.chain[i].kind == config::BlockKind::kCompensator) index = i;
  const config::BlockConfig& block = tuned.controller.chain[index];
  const YAML::Node original = config::yaml_at(YAML::Load(base.yaml_text), {"controller", "chain", index});
  YAML::Node entry(YAML::NodeType::Map);
  entry["kind"] = "compensator";
  for (const char* key : {"name", "prewarp_hz"})  // what a rational compensator keeps of the original entry
    if (original.IsMap() && original[key]) entry[key] = original[key];
  entry["model"] = "rational";
  auto numbers = [](const std::vector<double>& v) {
    YAML::Node n(YAML::NodeType::Sequence);
    for (const double x : v) n.push_back(exact(x));
    return n;
  };
  entry["numerator"] = numbers(block.numerator);
  entry["denominator"] = numbers(block.denominator);
  // A speed schedule chose its K for the controller the tune replaces: dropped (robodamp schedule writes one).
  const std::string text = base.controller.speed_schedule ? without_schedule(base.yaml_text) : base.yaml_text;
  return config::edit_yaml(text,
                           {{{"controller", "gain_ns_per_m"}, YAML::Node(exact(c.gain_ns_per_m)), "robodamp tune"},
                            {{"controller", "polarity"}, YAML::Node(c.polarity > 0 ? "+1" : "-1"), "robodamp tune"},
                            {{"controller", "chain", index}, entry, "robodamp tune"}});
}

}  // namespace robodamp::tune
