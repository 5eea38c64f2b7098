#include "analysis/sampled_plant.hpp"

#include "sim_plant/state_space.hpp"
#include "units/units.hpp"

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

PlantResponse SampledPlant::response(double f_hz) const {
  using ComplexD = std::complex<double>;
  const Eigen::Index nl = static_cast<Eigen::Index>(plant.locations.size());
  const ComplexD zi = std::exp(ComplexD(0.0, -kTwoPi * f_hz / loop_rate_hz));  // z^-1
  const Eigen::MatrixXcd r = resolvent(1.0 / zi);  // the late and early coil inputs, then the forces
  Eigen::MatrixXcd y(nl, 1 + nl);
  y.col(0) = r.col(0) + r.col(1) * zi;
  y.rightCols(nl) = r.rightCols(nl);
  const ComplexD delay = std::pow(zi, delay_steps);
  PlantResponse p;
  p.f_hz = f_hz;
  p.accel_per_volt.resize(static_cast<std::size_t>(nl));
  p.accel_per_force.assign(static_cast<std::size_t>(nl), std::vector<ComplexD>(static_cast<std::size_t>(nl)));
  for (Eigen::Index g = 0; g < nl; ++g) {
    p.accel_per_volt[static_cast<std::size_t>(g)] = (y(g, 0) + d_accel_coil(g, 0) * zi) * delay;
    for (Eigen::Index h = 0; h < nl; ++h)
      p.accel_per_force[static_cast<std::size_t>(g)][static_cast<std::size_t>(h)] =
          y(g, 1 + h) + d_accel_force(g, h) * zi;
  }
  p.sensor_response = sensor_model.response(f_hz);
  p.z_inverse = zi;
  return p;
}

std::shared_ptr<const std::vector<PlantResponse>> SampledPlant::sweep(const LogGrid& grid) const {
  const std::lock_guard<std::mutex> lock(sweeps_mutex_);  // a caller at a time: the first one fills it
  for (const auto& [g, responses] : sweeps_)
    if (g == grid) return responses;
  auto responses = std::make_shared<std::vector<PlantResponse>>();
  responses->reserve(static_cast<std::size_t>(grid.intervals) + 1);
  for (int i = 0; i <= grid.intervals; ++i) responses->push_back(response(grid.at(i)));
  sweeps_.emplace_back(grid, responses);
  return responses;
}

}  // namespace robodamp::analysis
