// Commissioning measurements at poses (`robodamp measure --pose` / `--poses`, docs/pose_dynamics.md) read
// back as the robot's driving-point receptance at each pose, for the pose-indexed model (`pose fit
// --measurements`). Each directory must carry the joint angles it was measured at.
#pragma once

#include <string>
#include <vector>

#include "config/robot_model_config.hpp"
#include "robot/pose_fit.hpp"

namespace robodamp::identify {

struct PoseMeasurements {
  std::vector<robot::MeasuredFrf> frfs;                     // name: the pose's name (or its directory's)
  std::vector<std::string> dirs;                            // the measurement directory of each
  std::string robot_model;                                  // the model file the joint angles refer to (the first's)
  robot::FrfDirection direction{robot::FrfDirection::kYY};  // the measured configuration's pose_schedule.axis
  double band_min_hz{5.0}, band_max_hz{100.0};              // its analysis band: where the FRFs are trusted
  int modes{0};  // its pose_schedule.modes: the plant's form the fit compares (robot::PoseFitSettings::modes)
};

// dirs: `measure --pose` directories (measurement.json) or `measure --poses` directories (poses.json: all
// their poses). location_id: whose driving-point FRF (frf_<id>_<id>.csv); 0: the location named TCP, else
// the first. Throws std::invalid_argument naming the directory and the reason: no measurement.json, no
// joint angles in it, a missing FRF, two measurements naming one pose, or two at the same pose (every joint
// within 0.5 deg) whose FRFs disagree by more than 20 % (weighted relative RMS over 0.5-2x the larger
// peak's frequency, inside the analysis band): contradicting data the model cannot fit both ways.
[[nodiscard]] PoseMeasurements read_pose_measurements(const std::vector<std::string>& dirs, int location_id = 0);

// Two measured poses whose FRFs differ by more than 20 % (the measure of read_pose_measurements' same-pose
// check) and by more than 3 times what the robot model puts between those poses: data the model cannot
// explain both ways (near poses the model's difference is small whatever its stiffnesses; far apart both
// differences saturate and nothing is refused). Refused.
// Throws std::invalid_argument naming both directories, both poses and the two differences; a pose
// outside the model's travel throws config::ConfigError with the pose.
void check_against_model(const PoseMeasurements& r, const config::RobotModelConfig& model);

// The weighted relative RMS difference of two receptances on a's frequencies (b interpolated), over
// [f_lo, f_hi] Hz, weights |a| / max|a|.
[[nodiscard]] double frf_difference(const robot::MeasuredFrf& a, const robot::MeasuredFrf& b, double f_lo_hz,
                                    double f_hi_hz);

}  // namespace robodamp::identify
