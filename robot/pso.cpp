#include "robot/pso.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace robodamp::robot {

PsoResult particle_swarm(const std::function<double(const std::vector<double>&)>& cost, const std::vector<double>& lo,
                         const std::vector<double>& hi, const PsoSettings& s) {
  const std::size_t d = lo.size();
  if (d == 0 || hi.size() != d || s.particles < 2 || s.iterations < 1)
    throw std::invalid_argument(
        "particle swarm: bounds of equal, non-zero length, at least 2 particles and 1 iteration");
  for (std::size_t j = 0; j < d; ++j)
    if (!(lo[j] < hi[j])) throw std::invalid_argument("particle swarm: each lower bound must be below its upper bound");
  std::mt19937_64 rng(s.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto n = static_cast<std::size_t>(s.particles);
  std::vector<std::vector<double>> x(n, std::vector<double>(d)), v(n, std::vector<double>(d)), best_x(n);
  std::vector<double> best_f(n);
  PsoResult r;
  r.best_cost = INFINITY;
  auto evaluate = [&](const std::vector<double>& p) {
    ++r.evaluations;
    const double f = cost(p);
    return std::isfinite(f) ? f : INFINITY;  // a model that cannot be evaluated is the worst
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < d; ++j) {
      x[i][j] = lo[j] + (hi[j] - lo[j]) * u(rng);
      v[i][j] = (hi[j] - lo[j]) * s.max_velocity_fraction * (2.0 * u(rng) - 1.0);
    }
    best_x[i] = x[i];
    best_f[i] = evaluate(x[i]);
    if (best_f[i] < r.best_cost) r.best_cost = best_f[i], r.best = x[i];
  }
  for (int it = 0; it < s.iterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < d; ++j) {
        const double vmax = (hi[j] - lo[j]) * s.max_velocity_fraction;
        v[i][j] = s.inertia * v[i][j] + s.cognitive * u(rng) * (best_x[i][j] - x[i][j]) +
                  s.social * u(rng) * (r.best[j] - x[i][j]);
        v[i][j] = std::clamp(v[i][j], -vmax, vmax);
        x[i][j] += v[i][j];
        if (x[i][j] < lo[j]) x[i][j] = lo[j], v[i][j] = -v[i][j];
        if (x[i][j] > hi[j]) x[i][j] = hi[j], v[i][j] = -v[i][j];
      }
      const double f = evaluate(x[i]);
      if (f < best_f[i]) {
        best_f[i] = f, best_x[i] = x[i];
        if (f < r.best_cost) r.best_cost = f, r.best = x[i];
      }
    }
    r.history.push_back(r.best_cost);
  }
  return r;
}

}  // namespace robodamp::robot
