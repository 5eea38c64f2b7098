// The structural and actuator model of the simulated plant, built from configuration (docs/physics.md
// section 1): FRF paths as sums of modes (Eq. 1) in the physical frame, the inertial actuator (Eq. 3)
// and one continuous state-space holding both, from which the time simulation and the discrete loop
// analysis are derived. Built off the real-time path; throws config::ConfigError on an inconsistent plant.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "sim_plant/state_space.hpp"

namespace robodamp::sim {

using Complex = std::complex<double>;

// (a + b s) / (s^2 + 2 zeta wn s + wn^2), physical frame (axis sign applied), m/N.
struct ModalTerm {
  double wn_rad_per_s{0.0};
  double damping_ratio{0.0};
  double a{0.0};
  double b{0.0};
};

// Force at location `excitation` -> displacement at location `response` (indices into locations).
struct FrfPath {
  std::string name;
  std::string origin;  // "robot.frfs[i]" or "reciprocal of <name>"
  std::size_t response{0};
  std::size_t excitation{0};
  std::vector<ModalTerm> modes;
  [[nodiscard]] Complex receptance(double f_hz) const;
  [[nodiscard]] double static_compliance_m_per_n() const;
};

struct ActuatorModel {  // Eq. 3
  double constant_n_per_v{4.8};
  double natural_freq_hz{9.0};
  double damping_ratio{0.15};
  double delay_s{0.0006};
  double force_limit_n{36.0};
  std::size_t location{0};
  // F/V with the delay, N/V.
  [[nodiscard]] Complex n_per_v(double f_hz) const;
};

struct PlantModel {
  std::vector<config::LocationConfig> locations;
  std::vector<FrfPath> paths;
  ActuatorModel actuator;
  double voltage_limit_v{10.0};
  std::vector<std::string> notes;  // assumptions taken while building (reciprocity, missing paths)

  // Inputs: [coil drive (V, after delay and limits), external force at each location (N)].
  // Outputs: [displacement (m), velocity (m/s), acceleration (m/s^2) at each location, actuator force (N)].
  // Acceleration and velocity are the left limits at a sample instant (the impulses that a held force
  // step causes through the residue-form b terms are not sampled).
  StateSpace ss;

  [[nodiscard]] std::size_t input_coil() const { return 0; }
  [[nodiscard]] std::size_t input_force(std::size_t loc) const { return 1 + loc; }
  [[nodiscard]] std::size_t output_displacement(std::size_t loc) const { return loc; }
  [[nodiscard]] std::size_t output_velocity(std::size_t loc) const { return locations.size() + loc; }
  [[nodiscard]] std::size_t output_acceleration(std::size_t loc) const { return 2 * locations.size() + loc; }
  [[nodiscard]] std::size_t output_actuator_force() const { return 3 * locations.size(); }

  // Index of a location id; throws std::out_of_range for an unknown id.
  [[nodiscard]] std::size_t index_of(int location_id) const;
  // Open-loop physical receptance (0 without a path), m/N.
  [[nodiscard]] Complex receptance(std::size_t response, std::size_t excitation, double f_hz) const;
  [[nodiscard]] const FrfPath* path(std::size_t response, std::size_t excitation) const;
};

// Requires robot.frfs; the loop needs a driving-point FRF at the actuator location and a path from the
// actuator to the sensor location (directly or by reciprocity).
[[nodiscard]] PlantModel build_plant_model(const config::Config& cfg);

}  // namespace robodamp::sim
