// A start for the compensator search drawn from the loop's phase at the robot's modes (docs/pose_dynamics.md,
// "Where a region's search starts"). Velocity feedback damps a mode, and cannot raise the receptance near it,
// while the actuator's force opposes the velocity there (its phase from -v near 0). The chain's filters, the
// actuator's own resonance and the delays turn that phase with frequency, so a compensator right at the
// dominant mode can be 20-60 deg wrong at the next one: where that mode is stiff at the TCP the loop then
// lifts the dominant mode's mass line over it instead of damping it. The shape here is the least squares of
// that phase over every mode in the band at every plant given, the compensator's own phase added to the
// chain's with a unity compensator; only the filters' arithmetic per evaluation, no loop analysis. Off the
// real-time path.
#pragma once

#include <optional>
#include <vector>

#include "config/config.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp::tune {

struct PhaseMatch {
  Candidate shape;            // the compensator and the better fitting polarity; K left at the default
  double rms_phase_deg{0.0};  // the fitted feedback's phase from -v, root mean square over the modes
  int modes{0};               // how many (plant, mode) pairs were fitted
};

// compensator_gain_max: the search's limit on the compensator's gain over its gain at the match frequency
// (TuneSettings::compensator_gain_max; 0: none), kept by a penalty. Nothing when no plant has a mode in
// [band_min_hz, band_max_hz]. Throws config::ConfigError when a plant's chain has no compensator block.
[[nodiscard]] std::optional<PhaseMatch> phase_matched(const std::vector<config::Config>& plants, double band_min_hz,
                                                      double band_max_hz, double compensator_gain_max);

}  // namespace robodamp::tune
