// The controller's command on a quiet cell (no cut, no hit), predicted from the discrete loop that runs:
// the sensor's white noise and ADC rounding, and the robot's drive vibration (disturbance.*), through
// the closed loop to the command. A compensator with a slow, lightly damped pole turns the noise into a
// slow, swelling command that the supervisor's instability detector eventually takes for a growing
// oscillation (docs/tuning.md, "The quiet command"). Off the real-time path.
#pragma once

#include "analysis/loop_model.hpp"

namespace robodamp::analysis {

struct QuietCommand {
  double noise_rms_v{0.0};      // from the sensor's noise and the ADC's rounding (white over 0..fs/2)
  double vibration_rms_v{0.0};  // from the drive vibration (a sine at disturbance.drive_vibration_hz)
  double rms_v{0.0};            // both
  double peak_density_hz{0.0};  // where the noise's command density peaks
};

[[nodiscard]] QuietCommand quiet_command(const LoopModel& m, double gain_ns_per_m, int polarity);

}  // namespace robodamp::analysis
