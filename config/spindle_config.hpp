// The spindle the damper works beside (docs/harmonic_notch.md): its tooth count and speed range, and the
// controller's spindle-locked harmonic notches (controller.harmonic_notch), which follow the tooth-passing
// frequency spindle speed x teeth / 60.
#pragma once

#include <optional>
#include <string>

namespace robodamp::config {

struct HarmonicNotchConfig {
  int harmonics{3};            // notches at 1..harmonics x the tooth frequency
  double bandwidth_hz{10.0};   // -3 dB width of each notch
  double depth_db{30.0};       // attenuation at each centre
  double slew_fraction{0.05};  // largest centre move per update, relative to the centre
  double min_hz{10.0};         // below it the bank parks and fades out
  double fade_s{0.2};
  double update_hz{100.0};
};

struct SpindleConfig {
  int teeth{3};
  double rpm_max{30000.0};  // a requested speed above it is refused (and parks the notches)
  // The milling job the cell cuts (config/milling/*.yaml), for live stability: its depth and the
  // open and damped limits at the spindle speed now. Resolved relative to the configuration file.
  std::string job;  // as written; empty = no live stability
  std::string job_resolved;
  std::string structure;  // the job's structure to use (empty: the job's own)
  // With pose_schedule: the live limits are for the robot at its pose, rounded to this grid (a new grid
  // point is a new computation; docs/pose_dynamics.md, "Live stability at the pose").
  double pose_step_deg{2.0};
  // Spindle-speed advice (docs/milling.md, "Spindle-speed advice"): the uniform candidates over the range
  // beside the pockets the chatter frequency and the modes name. Each costs an accurate limit at every pose
  // checked (the pose now and the path ahead), about a second on a cell PC's core; fewer answer sooner and
  // may miss a pocket the frequencies do not name.
  int advice_grid_points{48};
  // The HIL emulator's robot follows robodamp's spindle-speed advice (modbus.robot.advice_register) in
  // its regenerative cut: an advised speed inside 0 < rpm <= rpm_max replaces the program's speed.
  bool apply_advice{false};
};

}  // namespace robodamp::config
