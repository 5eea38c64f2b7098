#include "robot/robot_model.hpp"

#include <cmath>

namespace robodamp::robot {

ChainModel chain_model(const config::RobotModelConfig& cfg) {
  ChainModel m;
  for (const auto& l : cfg.links)
    m.links.push_back({l.length_m, l.mass_kg, l.bending_stiffness_nm2, l.axial_stiffness_n, l.elements});
  for (const auto& j : cfg.joints)
    m.joints.push_back({j.stiffness_nm_per_rad, j.damping_ratio, j.translational_stiffness_n_per_m});
  m.head_mass_kg = cfg.head_mass_kg;
  m.head_inertia_kgm2 = cfg.head_inertia_kgm2;
  return m;
}

PlanarChain at_pose(const config::RobotModelConfig& cfg, const std::vector<double>& joints_deg) {
  if (auto p = config::pose_problem(cfg, joints_deg))
    throw config::ConfigError({config::Problem{cfg.source, {}, "pose", *p}});
  std::vector<double> q;
  for (double d : joints_deg) q.push_back(d * M_PI / 180.0);
  return PlanarChain(chain_model(cfg), q);
}

}  // namespace robodamp::robot
