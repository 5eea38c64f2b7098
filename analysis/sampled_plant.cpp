#include "analysis/sampled_plant.hpp"

#include "sim_plant/state_space.hpp"

namespace robodamp::analysis {

SampledPlant::SampledPlant(const config::Config& cfg)
    : plant(sim::build_plant_model(cfg)),
      sensor_model(cfg.sensor, cfg.loop.rate_hz, 0),
      sensor(plant.index_of(cfg.sensor.location)),
      loop_rate_hz(cfg.loop.rate_hz) {
  const double t = 1.0 / cfg.loop.rate_hz;
  const auto& ss = plant.ss;
  const Eigen::Index nu = ss.b.cols(), nl = static_cast<Eigen::Index>(plant.locations.size());
  const sim::DelayedZoh coil = sim::discretise_zoh_delayed(ss.a, ss.b.leftCols(1), t, plant.actuator.delay_s);
  const sim::Zoh forces = sim::discretise_zoh(ss.a, ss.b.rightCols(nu - 1), t);
  phi = coil.phi;
  gamma_late = coil.gamma_late;
  gamma_early = coil.gamma_early;
  gamma_force = forces.gamma;
  delay_steps = coil.steps;
  c_accel = ss.c.middleRows(2 * nl, nl);
  d_accel_coil = ss.d.block(2 * nl, 0, nl, 1);
  d_accel_force = ss.d.block(2 * nl, 1, nl, nl);
  Eigen::MatrixXd inputs(phi.rows(), 2 + nl);
  inputs << gamma_late, gamma_early, gamma_force;
  resolvent = Resolvent(phi, inputs, c_accel);
}

}  // namespace robodamp::analysis
