// The plant as the damping loop samples it (docs/physics.md §1): the structure and actuator (sim::PlantModel),
// the configured sensor, and the plant discretised exactly with zero-order hold at the loop rate with the
// actuator's delay, with the resolvent its frequency responses come from. What the controller does not change:
// a loop model and its harmonic-notch variants at every spindle speed share one (LoopModel::at_speed). Off the
// real-time path.
#pragma once

#include <cmath>
#include <complex>
#include <cstddef>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "analysis/resolvent.hpp"
#include "config/config.hpp"
#include "sim_plant/plant_model.hpp"
#include "sim_plant/sensor.hpp"

namespace robodamp::analysis {

// The plant's discrete transfers at one frequency: sampled acceleration at each location per held
// coil voltage and per held external force at each location (sample at t_k per input held over [k, k+1)),
// and the sensor's own response there (its analog coupling: what the controller reads per m/s^2).
struct PlantResponse {
  double f_hz{0.0};
  std::vector<std::complex<double>> accel_per_volt;                // [location]
  std::vector<std::vector<std::complex<double>>> accel_per_force;  // [response][excitation]
  std::complex<double> sensor_response{1.0, 0.0};
  std::complex<double> z_inverse{1.0, 0.0};  // e^{-j 2 pi f / fs}: the loop's one sample of computation delay
};

// intervals + 1 frequencies from lo_hz to hi_hz, evenly spaced in log: lo (hi / lo)^(i / intervals).
struct LogGrid {
  double lo_hz{0.0}, hi_hz{0.0};
  int intervals{0};
  [[nodiscard]] double at(int i) const { return lo_hz * std::pow(hi_hz / lo_hz, static_cast<double>(i) / intervals); }
  [[nodiscard]] bool operator==(const LogGrid&) const = default;
};

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

  // The plant's discrete transfers at f_hz (LoopModel::plant_response).
  [[nodiscard]] PlantResponse response(double f_hz) const;
  // response() at every point of a grid the loop's analyses sweep whatever the controller (the margins', the
  // quiet command's): computed once per grid on first use, from any thread, and shared by every loop model on
  // this plant (LoopModel::with_controller: a tune's candidates).
  [[nodiscard]] std::shared_ptr<const std::vector<PlantResponse>> sweep(const LogGrid& grid) const;

 private:
  mutable std::mutex sweeps_mutex_;
  mutable std::vector<std::pair<LogGrid, std::shared_ptr<const std::vector<PlantResponse>>>> sweeps_;
};

}  // namespace robodamp::analysis
