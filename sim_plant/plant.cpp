#include "sim_plant/plant.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace robodamp::sim {

Plant::Plant(PlantModel model, const config::Config& cfg)
    : model_(std::move(model)),
      period_s_(1.0 / cfg.loop.rate_hz),
      oversampling_(cfg.plant.oversampling),
      h_s_(period_s_ / cfg.plant.oversampling),
      sensor_(cfg.sensor, cfg.loop.rate_hz, cfg.disturbances.seed * 0x9E3779B97F4A7C15ULL + 1),
      sensor_loc_(model_.index_of(cfg.sensor.location)) {
  const Matrix& b = model_.ss.b;
  const Eigen::Index nu = b.cols(), n = model_.ss.a.rows(), nl = nu - 1;
  // The coil drive is delayed (Eq. 3's t_a); the external forces are not.
  zoh_ = discretise_zoh_delayed(model_.ss.a, b.leftCols(1), h_s_, model_.actuator.delay_s);
  const Zoh forces = discretise_zoh(model_.ss.a, b.rightCols(nl), h_s_);
  Matrix step(n, n + 2 + nl);
  step << zoh_.phi, zoh_.gamma_late, zoh_.gamma_early, forces.gamma;
  Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> pattern(n, n + 2 + nl);
  pattern.setConstant(true);
  pattern.leftCols(n) = model_.pattern;  // exact zeros of e^{Ah} stay zeros
  step_ = SparseRows(step, &pattern);
  c_ = SparseRows(model_.ss.c);
  d_ = SparseRows(model_.ss.d);
  n_ = static_cast<std::size_t>(n);
  z_.assign(n_ + 2 + static_cast<std::size_t>(nl), 0.0);
  x_next_.assign(n_, 0.0);
  u_.assign(static_cast<std::size_t>(nu), 0.0);
  coil_history_.assign(static_cast<std::size_t>(zoh_.steps) + 2, 0.0);
  period_force_.assign(model_.locations.size(), 0.0);
}

void Plant::reset() {
  std::fill(z_.begin(), z_.end(), 0.0);
  std::fill(u_.begin(), u_.end(), 0.0);
  std::fill(coil_history_.begin(), coil_history_.end(), 0.0);
  std::fill(period_force_.begin(), period_force_.end(), 0.0);
  std::fill(period_excitation_force_.begin(), period_excitation_force_.end(), 0.0);
  history_pos_ = 0;
  internal_steps_ = 0;
  counters_ = {};
  sensor_.reset();
}

std::size_t Plant::nonzeros_per_step() const { return step_.nonzeros(); }

void Plant::step(double drive_v) noexcept {
  const std::size_t nl = model_.locations.size();
  const std::size_t hist = coil_history_.size();
  const auto delay = static_cast<std::size_t>(zoh_.steps);
  double* force = z_.data() + n_ + 2;
  std::fill(period_force_.begin(), period_force_.end(), 0.0);
  std::fill(period_excitation_force_.begin(), period_excitation_force_.end(), 0.0);
  // Amplifier voltage range, then the actuator's coil force limit (faults may lower it to zero).
  double v = std::isfinite(drive_v) ? drive_v : 0.0;
  bool clipped = false;
  if (std::abs(v) > model_.voltage_limit_v) v = std::copysign(model_.voltage_limit_v, v), clipped = true;
  for (int i = 0; i < oversampling_; ++i) {
    const double t = static_cast<double>(internal_steps_) * h_s_;
    double vi = v;
    const double limit_v = faults_.actuator_force_limit_n(t, model_.actuator.force_limit_n) / model_.actuator.constant_n_per_v;
    if (std::abs(vi) > limit_v) {
      vi = std::copysign(limit_v, vi);
      ++counters_.force_limited;
    }
    if (clipped) ++counters_.voltage_clipped;
    // Ring of the coil drive: u[k - delay] and u[k - delay - 1].
    coil_history_[history_pos_] = vi;
    const std::size_t late = history_pos_ >= delay ? history_pos_ - delay : history_pos_ + hist - delay;
    const std::size_t early = late == 0 ? hist - 1 : late - 1;
    if (++history_pos_ == hist) history_pos_ = 0;
    z_[n_] = coil_history_[late];
    z_[n_ + 1] = coil_history_[early];
    for (std::size_t l = 0; l < nl; ++l) force[l] = 0.0;
    for (std::size_t e = 0; e < excitations_.size(); ++e) {
      const double f = excitations_[e]->force_n(t, h_s_);
      force[excitations_[e]->location()] += f;
      period_excitation_force_[e] += f;
    }
    for (std::size_t l = 0; l < nl; ++l) period_force_[l] += force[l];
    step_.apply(z_.data(), x_next_.data());
    std::copy(x_next_.begin(), x_next_.end(), z_.begin());
    ++internal_steps_;
  }
  const double inv = 1.0 / oversampling_;
  for (auto& f : period_force_) f *= inv;
  for (auto& f : period_excitation_force_) f *= inv;
  // Left limits at the end of the period: the inputs of the last internal step.
  u_[0] = z_[n_];
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
  const double w = 2.0 * M_PI * d.drive_vibration_hz;
  const double accel_per_n = w * w * std::abs(model.receptance(sensor, at, d.drive_vibration_hz));
  const double amplitude = accel_per_n > 0.0 ? d.drive_vibration_mps2 / accel_per_n : 0.0;
  std::mt19937_64 rng(d.seed);
  const double phase = std::uniform_real_distribution<double>(0.0, 2.0 * M_PI)(rng);
  return std::make_unique<Sine>(at, amplitude, d.drive_vibration_hz, phase);
}

}  // namespace robodamp::sim
