// The harmonic notches across the spindle's speed range (docs/harmonic_notch.md, "Across the speed
// range"): at each speed of a grid, the loop with the notches there (analysis::LoopModel's spindle_rpm)
// at the configured K: is it stable, and does every mode that the loop damps without the notches stay
// inside its damping window? Speeds where either fails are refused: the controller parks the notches
// there instead (control::ControllerParams::refused_rpm). Off the real-time path, at configuration time.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "control/controller_params.hpp"

namespace robodamp::analysis {

class LoopModel;

struct NotchSpeedPoint {
  double rpm{0.0}, tooth_hz{0.0};
  std::size_t notches{0};
  double spectral_radius{0.0};
  bool stable{false};
  std::vector<double> mode_hz, notch_phase_deg;  // the loop path's modes and what the notches cost there
  bool refused{false};
  std::string reason;
};

struct NotchSpeedMap {
  std::vector<NotchSpeedPoint> points;
  std::vector<std::pair<double, double>> refused_rpm;  // merged intervals, widened to the accepted neighbours
};

// Log-spaced from where the notches start (min_hz x 60 / teeth) to spindle.rpm_max; empty without
// controller.harmonic_notch.
[[nodiscard]] NotchSpeedMap notch_speed_map(const config::Config& cfg, int points = 400);
// The same from the loop without notches (its configuration's): every speed's loop shares its sampled plant.
// Throws std::invalid_argument for a model built at a spindle speed (its notches are not the plain loop).
[[nodiscard]] NotchSpeedMap notch_speed_map(const LoopModel& plain, int points = 400);

// The map's refused intervals into the controller's parameters; more than it holds are merged across
// the smallest gaps (refusing a little more, never less).
void apply_refused_speeds(const NotchSpeedMap& map, control::ControllerParams& p);

}  // namespace robodamp::analysis
