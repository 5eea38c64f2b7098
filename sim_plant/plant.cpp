#include "sim_plant/plant.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace robodamp::sim {

Plant::Plant(PlantModel model, const config::Config& cfg)
    : model_(std::move(model)),
      period_s_(1.0 / cfg.loop.rate_hz),
      oversampling_(cfg.plant.oversampling),
      h_s_(period_s_ / cfg.plant.oversampling),
      sensor_(cfg.sensor, cfg.loop.rate_hz, cfg.disturbances.seed * 0x9E3779B97F4A7C15ULL + 1),
      sensor_loc_(model_.index_of(cfg.sensor.location)) {
  const Matrix& b = model_.ss.b;
  const Eigen::Index nu = b.cols(), nl = nu - 1;
  // The coil drive is delayed (Eq. 3's t_a); the external forces are not.
  zoh_ = discretise_zoh_delayed(model_.ss.a, b.leftCols(1), h_s_, model_.actuator.delay_s);
  const Zoh forces = discretise_zoh(model_.ss.a, b.rightCols(nl), h_s_);
  step_ = ModalStep(model_.ss, zoh_, forces.gamma);
  nominal_limit_v_ = model_.actuator.force_limit_n / std::abs(model_.actuator.constant_n_per_v);
  inv_oversampling_ = 1.0 / oversampling_;
  wiring_ = cfg.plant.actuator_wiring;
  force_.assign(static_cast<std::size_t>(nl), 0.0);
  u_.assign(static_cast<std::size_t>(nu), 0.0);
  coil_history_.assign(static_cast<std::size_t>(zoh_.steps) + 2, 0.0);
  period_force_.assign(model_.locations.size(), 0.0);
}

void Plant::retune(PlantModel model) {
  if (model.locations.size() != model_.locations.size())
    throw std::invalid_argument("Plant::retune: the new structure has " + std::to_string(model.locations.size()) +
                                " locations, the plant " + std::to_string(model_.locations.size()));
  const Vector x = step_.state();
  model_ = std::move(model);
  const Matrix& b = model_.ss.b;
  zoh_ = discretise_zoh_delayed(model_.ss.a, b.leftCols(1), h_s_, model_.actuator.delay_s);
  const Zoh forces = discretise_zoh(model_.ss.a, b.rightCols(b.cols() - 1), h_s_);
  step_ = ModalStep(model_.ss, zoh_, forces.gamma);
  if (static_cast<std::size_t>(x.size()) == step_.states()) {
    step_.set_state(x);
  } else {
    Vector y = Vector::Zero(static_cast<Eigen::Index>(step_.states()));
    y.head(2) = x.head(2);
    step_.set_state(y);
  }
}

void Plant::reset() {
  step_.reset();
  std::fill(force_.begin(), force_.end(), 0.0);
  std::fill(u_.begin(), u_.end(), 0.0);
  std::fill(coil_history_.begin(), coil_history_.end(), 0.0);
  std::fill(period_force_.begin(), period_force_.end(), 0.0);
  std::fill(period_excitation_force_.begin(), period_excitation_force_.end(), 0.0);
  history_pos_ = 0;
  internal_steps_ = 0;
  counters_ = {};
  sensor_.reset();
}

void Plant::step(double drive_v) noexcept {
  const std::size_t nl = model_.locations.size();
  const std::size_t hist = coil_history_.size();
  const auto delay = static_cast<std::size_t>(zoh_.steps);
  double* force = force_.data();
  for (double& f : period_force_) f = 0.0;
  for (double& f : period_excitation_force_) f = 0.0;
  // Amplifier voltage range, then the actuator's coil force limit (faults may lower it to zero).
  double v = std::isfinite(drive_v) ? drive_v : 0.0;
  bool clipped = false;
  if (std::abs(v) > model_.voltage_limit_v) v = std::copysign(model_.voltage_limit_v, v), clipped = true;
  for (int i = 0; i < oversampling_; ++i) {
    const double t = static_cast<double>(internal_steps_) * h_s_;
    double vi = v;
    const double limit_v = faults_.empty() ? nominal_limit_v_
                                           : faults_.actuator_force_limit_n(t, model_.actuator.force_limit_n) /
                                                 std::abs(model_.actuator.constant_n_per_v);
    if (std::abs(vi) > limit_v) {
      vi = std::copysign(limit_v, vi);
      ++counters_.force_limited;
    }
    if (clipped) ++counters_.voltage_clipped;
    // Ring of the coil drive: u[k - delay] and u[k - delay - 1].
    coil_history_[history_pos_] = wiring_ * vi;  // swapped leads push the other way
    const std::size_t late = history_pos_ >= delay ? history_pos_ - delay : history_pos_ + hist - delay;
    const std::size_t early = late == 0 ? hist - 1 : late - 1;
    if (++history_pos_ == hist) history_pos_ = 0;
    for (std::size_t l = 0; l < nl; ++l) force[l] = 0.0;
    for (std::size_t e = 0; e < excitations_.size(); ++e) {
      const double f = excitations_[e]->force_n(t, h_s_);
      force[excitations_[e]->location()] += f;
      period_excitation_force_[e] += f;
    }
    for (std::size_t l = 0; l < nl; ++l) period_force_[l] += force[l];
    step_.advance(coil_history_[late], coil_history_[early], force);
    u_[0] = coil_history_[late];
    ++internal_steps_;
  }
  for (auto& f : period_force_) f *= inv_oversampling_;
  for (auto& f : period_excitation_force_) f *= inv_oversampling_;
  // Left limits at the end of the period: the inputs of the last internal step.
  for (std::size_t l = 0; l < nl; ++l) u_[1 + l] = force[l];
  ++counters_.steps;
}

SensorReading Plant::sense() noexcept {
  const double measured = sensor_.measure(acceleration_mps2(sensor_loc_));
  return faults_.apply_sensor(time_s(), period_s_, measured);
}

std::unique_ptr<Excitation> make_drive_vibration(const PlantModel& model, const config::Config& cfg) {
  const auto& d = cfg.disturbances;
  const std::size_t at = model.index_of(d.drive_vibration_location), sensor = model.index_of(cfg.sensor.location);
  const double w = kTwoPi * d.drive_vibration_hz;
  const double accel_per_n = w * w * std::abs(model.receptance(sensor, at, d.drive_vibration_hz));
  const double amplitude = accel_per_n > 0.0 ? d.drive_vibration_mps2 / accel_per_n : 0.0;
  std::mt19937_64 rng(d.seed);
  const double phase = std::uniform_real_distribution<double>(0.0, kTwoPi)(rng);
  return std::make_unique<Sine>(at, amplitude, d.drive_vibration_hz, phase);
}

}  // namespace robodamp::sim
