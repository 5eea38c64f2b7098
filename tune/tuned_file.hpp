// The file `robodamp tune` writes: the configuration it started from with the tuned compensator (a
// rational block in the chain's compensator entry), gain and polarity set as data (config/yaml_edit.hpp),
// in whatever YAML style the configuration is written, its comments kept where the edit is exact.
#pragma once

#include <string>

#include "config/config.hpp"
#include "config/yaml_edit.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp::tune {

// The shortest decimal text that reads back as exactly x: a written file holds the verified numbers.
[[nodiscard]] std::string exact(double x);

// base: a configuration with a compensator in its chain (Evaluator refuses one without); base.yaml_text is
// edited, without its controller.speed_schedule (it chose K for the controller the tune replaces; run robodamp
// schedule on the tuned file). Throws std::invalid_argument when the text cannot be edited to read back.
[[nodiscard]] config::EditedYaml tuned_config_text(const config::Config& base, const Candidate& c);

}  // namespace robodamp::tune
