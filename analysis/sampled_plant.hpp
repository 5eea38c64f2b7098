// The plant as the damping loop samples it (docs/physics.md §1): the structure and actuator (sim::PlantModel),
// the configured sensor, and the plant discretised exactly with zero-order hold at the loop rate with the
// actuator's delay, with the resolvent its frequency responses come from. What the controller does not change:
// a loop model and its harmonic-notch variants at every spindle speed share one (LoopModel::at_speed). Off the
// real-time path.
#pragma once

#include <cstddef>

#include <Eigen/Dense>

#include "analysis/resolvent.hpp"
#include "config/config.hpp"
#include "sim_plant/plant_model.hpp"
#include "sim_plant/sensor.hpp"

namespace robodamp::analysis {

struct SampledPlant {
  // Throws config::ConfigError where the configuration's plant cannot be built (sim::build_plant_model).
  explicit SampledPlant(const config::Config& cfg);

  sim::PlantModel plant;
  sim::Accelerometer sensor_model;
  std::size_t sensor{0};  // the sensor's location index
  double loop_rate_hz{0.0};
  // x[k+1] = phi x + gamma_late w[k] + gamma_early w[k-1] + gamma_force f[k]: w the coil drive (its delay
  // split over the two held samples), f the external forces at the locations.
  Eigen::MatrixXd phi, gamma_late, gamma_early, gamma_force;
  // Sampled acceleration at the locations: c_accel x + d_accel_coil w + d_accel_force f.
  Eigen::MatrixXd c_accel, d_accel_coil, d_accel_force;
  int delay_steps{0};   // whole samples of the actuator's delay
  Resolvent resolvent;  // c_accel (z I - phi)^-1 [gamma_late, gamma_early, gamma_force]
};

}  // namespace robodamp::analysis
