// A milling job's time-domain cut and its semi-discretization set up from the job file (tool, material,
// cut, structure, time_domain section) with command-line overrides, and checked: every number named with
// its value, unit and allowed range when refused (config::ConfigError). Off the real-time path.
#pragma once

#include <optional>
#include <vector>

#include "config/milling_config.hpp"
#include "milling/cut_simulation.hpp"
#include "milling/cut_stability.hpp"
#include "milling/structure.hpp"
#include "milling/tool_dynamics.hpp"

namespace robodamp::milling {

struct CutOverrides {
  std::optional<double> rpm, axial_mm, radial_mm;
  std::optional<int> revolutions;
  bool damped{false};  // with the damping controller running (the structure needs a controller part)
};

struct CutJob {
  std::vector<CutterModalTerm> terms;
  Cutter cutter;
  config::MaterialConfig material;
  CutSettings settings;  // with the damper: steps of one loop period, rpm the nearest whose tooth
                         // period is a whole number of them
  double requested_rpm{0.0};
  double highest_mode_hz{0.0};
  bool damped{false};
  DynamicsFactory dynamics;  // fresh structure dynamics for each cut (refers to the Structure given)
};

// Throws config::ConfigError naming the option (e.g. --radial-mm) or the job key that does not fit.
[[nodiscard]] CutJob make_cut_job(const config::MillingConfig& cfg, const Structure& structure, const CutOverrides& o);
// One cut of the job (with the actuator's peak force and saturation time when damped).
[[nodiscard]] CutOutcome run_job(const CutJob& job);

}  // namespace robodamp::milling
