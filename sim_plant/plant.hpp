// The simulated plant in time: the state-space of PlantModel discretised exactly (zero-order hold on the
// amplifier voltage and the external forces) at loop rate x oversampling, with the actuator delay exact
// at the internal rate, the amplifier's voltage range and the actuator's force limit, the control
// accelerometer, excitations and faults. Construction allocates; step() and the readers are RT-safe.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "config/config.hpp"
#include "sim_plant/excitation.hpp"
#include "sim_plant/faults.hpp"
#include "sim_plant/modal_step.hpp"
#include "sim_plant/plant_model.hpp"
#include "sim_plant/sensor.hpp"
#include "sim_plant/state_space.hpp"

namespace robodamp::sim {

struct PlantCounters {
  std::uint64_t steps{0};            // loop periods
  std::uint64_t voltage_clipped{0};  // internal steps with the amplifier at its voltage range
  std::uint64_t force_limited{0};    // internal steps with the actuator coil force at its limit
};

class Plant {
 public:
  Plant(PlantModel model, const config::Config& cfg);

  // Before a run (allocates).
  // Returns the excitation's index for excitation_force_n().
  std::size_t add_excitation(std::unique_ptr<Excitation> e) {
    excitations_.push_back(std::move(e));
    period_excitation_force_.push_back(0.0);
    return excitations_.size() - 1;
  }
  void clear_excitations() {
    excitations_.clear();
    period_excitation_force_.clear();
  }
  FaultInjector& faults() { return faults_; }
  // Zero state, empty delay line, time 0, counters cleared; excitations and faults stay.
  void reset();
  // The same plant with another structure (the robot at another pose; same locations and actuator):
  // the discretisation is rebuilt and the state carried over mode block by mode block (frozen
  // coefficients: right while the modes move slowly against their periods); with another number of
  // modes only the actuator's state is kept. Allocates: between steps, off the controller's path.
  void retune(PlantModel model);

  // RT-safe. One loop period with the amplifier input held at drive_v.
  void step(double drive_v) noexcept;
  // RT-safe. The control accelerometer's reading at the current instant (call once per loop tick).
  [[nodiscard]] SensorReading sense() noexcept;

  // True outputs at the current instant (left limits), m, m/s, m/s^2, N.
  // Each is evaluated when read (C x + D u of its row).
  [[nodiscard]] double displacement_m(std::size_t loc) const { return output(model_.output_displacement(loc)); }
  [[nodiscard]] double velocity_mps(std::size_t loc) const { return output(model_.output_velocity(loc)); }
  [[nodiscard]] double acceleration_mps2(std::size_t loc) const { return output(model_.output_acceleration(loc)); }
  [[nodiscard]] double actuator_force_n() const { return output(model_.output_actuator_force()); }
  // Mean external force at a location over the last period (what a force sensor sampled at the loop
  // rate through its anti-aliasing sees, to first order), N.
  [[nodiscard]] double external_force_n(std::size_t loc) const { return period_force_[loc]; }
  // The same for one excitation alone (e.g. what the impact hammer's load cell measures), N.
  [[nodiscard]] double excitation_force_n(std::size_t i) const { return period_excitation_force_[i]; }

  [[nodiscard]] double time_s() const { return static_cast<double>(counters_.steps) * period_s_; }
  [[nodiscard]] double period_s() const { return period_s_; }
  [[nodiscard]] int oversampling() const { return oversampling_; }
  [[nodiscard]] const PlantCounters& counters() const { return counters_; }
  [[nodiscard]] const PlantModel& model() const { return model_; }
  [[nodiscard]] const DelayedZoh& discretisation() const { return zoh_; }
  [[nodiscard]] Accelerometer& sensor() { return sensor_; }
  [[nodiscard]] std::size_t sensor_location() const { return sensor_loc_; }
  [[nodiscard]] std::size_t state_count() const { return step_.states(); }
  [[nodiscard]] std::size_t mode_blocks() const { return step_.mode_blocks(); }
  // The state in PlantModel::ss's order (tests; allocates).
  [[nodiscard]] Vector state() const { return step_.state(); }

 private:
  [[nodiscard]] double output(std::size_t row) const noexcept { return step_.output(row, u_.data()); }
  PlantModel model_;
  double period_s_;
  int oversampling_;
  double h_s_;
  double inv_oversampling_{1.0};
  double wiring_{1.0};           // plant.actuator_wiring: -1 when the amplifier's leads are swapped
  double nominal_limit_v_{0.0};  // the actuator's force limit as coil voltage, V
  DelayedZoh zoh_;
  // One internal step in modal block form: x[k+1] = phi x + gamma_late u[k-d] + gamma_early u[k-d-1]
  // + gamma_force f[k].
  ModalStep step_;
  std::vector<double> force_;         // external force per location over the current internal step, N
  std::vector<double> u_;             // inputs of the last internal step (for the left limits)
  std::vector<double> coil_history_;  // delay line of the coil drive at the internal rate
  std::size_t history_pos_{0};
  std::vector<double> period_force_;
  std::vector<double> period_excitation_force_;
  std::vector<std::unique_ptr<Excitation>> excitations_;
  FaultInjector faults_;
  Accelerometer sensor_;
  std::size_t sensor_loc_;
  std::uint64_t internal_steps_{0};
  PlantCounters counters_{};
};

// The robot's inherent vibration with the drives on (docs/physics.md §1: about 3 Hz): a sine force at
// the configured location sized for the configured open-loop acceleration amplitude at the sensor.
[[nodiscard]] std::unique_ptr<Excitation> make_drive_vibration(const PlantModel& model, const config::Config& cfg);

}  // namespace robodamp::sim
