// Particle swarm optimisation (Kennedy and Eberhart, with Clerc's constriction coefficients), bounded,
// seeded and deterministic: what the planar-robot study fits its robot's equivalent parameters with. No Debian
// package offers PSO (NLopt's global methods are DIRECT, CRS, ISRES, ESCH, MLSL), hence this small one.
// Off the real-time path.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace robodamp::robot {

struct PsoSettings {
  int particles{40};
  int iterations{150};
  std::uint64_t seed{1};
  double inertia{0.7298};  // Clerc's constriction: chi = 0.7298, c1 = c2 = chi x 2.05
  double cognitive{1.49618};
  double social{1.49618};
  double max_velocity_fraction{0.2};  // of each bound's width per iteration
};

struct PsoResult {
  std::vector<double> best;
  double best_cost{0.0};
  std::vector<double> history;  // best cost after each iteration
  int evaluations{0};
};

// Minimises cost over the box [lo, hi]; particles leaving it are put back on the bound with their
// velocity there reversed.
[[nodiscard]] PsoResult particle_swarm(const std::function<double(const std::vector<double>&)>& cost,
                                       const std::vector<double>& lo, const std::vector<double>& hi,
                                       const PsoSettings& s = {});

}  // namespace robodamp::robot
