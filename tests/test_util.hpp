#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "config/config.hpp"
#include "control/chain_design.hpp"

namespace robodamp::test {

inline std::string preset(const std::string& name) {
  return std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/" + name + ".yaml";
}

inline control::ChainDesign design_preset(const std::string& name, double rate_hz = 0.0) {
  config::Config c = config::load_config_file(preset(name));
  if (rate_hz > 0.0) c.loop.rate_hz = rate_hz;
  return control::design_chain(c);
}

inline std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Wrapped phase difference in degrees.
inline double phase_diff_deg(double a, double b) {
  double d = a - b;
  while (d > 180.0) d -= 360.0;
  while (d <= -180.0) d += 360.0;
  return d;
}

}  // namespace robodamp::test
