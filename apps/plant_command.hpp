// `robodamp plant`: the HIL plant emulator (hil/plant_emulator.hpp) as a process of its own.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace robodamp::apps {

struct PlantOptions {
  std::string config_path;
  std::optional<config::HilPacing> pacing;
  double duration_s{0.0};
  std::string json_path;
  bool impacts{true};
  int impact_location{0};
  std::vector<std::string> mounting_schedule;  // "T:vertical" / "T:horizontal", plant time in s
};

// 0 served a controller to the end; 2 configuration or option error; 1 could not set up or the
// impact schedule did not complete.
[[nodiscard]] int run_plant(const PlantOptions& o);

}  // namespace robodamp::apps
