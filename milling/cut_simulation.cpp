#include "milling/cut_simulation.hpp"

#include "milling/cut_process.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robodamp::milling {

int steps_per_tooth(const config::TimeDomainConfig& td, double highest_mode_hz, double rpm, int teeth) {
  if (td.steps_per_tooth > 0) return td.steps_per_tooth;
  const double tooth_period_s = 60.0 / (rpm * teeth);
  return std::max(40, static_cast<int>(std::ceil(td.min_steps_per_mode_period * highest_mode_hz * tooth_period_s)));
}

CutRecord simulate_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                       const config::MaterialConfig& mat, const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1)
    throw std::invalid_argument("simulate_cut: needs rpm > 0 and steps_per_tooth >= 1");
  ToolDynamics dyn(terms, 60.0 / (s.rpm * cutter.teeth) / s.steps_per_tooth);
  return simulate_cut(dyn, cutter, mat, s);
}

CutRecord simulate_cut(CutDynamics& dyn, const Cutter& cutter, const config::MaterialConfig& mat,
                       const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1 || s.revolutions <= s.settle_revolutions)
    throw std::invalid_argument("simulate_cut: needs rpm > 0, steps_per_tooth >= 1, revolutions > settle_revolutions");
  CutProcess process(cutter, mat, s);
  const double h = process.step_s();
  if (std::abs(dyn.step_s() - h) > 1e-9 * h)
    throw std::invalid_argument("simulate_cut: the dynamics' step is not the tooth period / steps_per_tooth");
  const std::size_t bins = process.steps_per_revolution();
  CutRecord r;
  r.rpm = s.rpm, r.step_s = h, r.teeth = cutter.teeth, r.steps_per_tooth = s.steps_per_tooth;
  const std::size_t steps = bins * static_cast<std::size_t>(s.revolutions);
  r.settle_steps = bins * static_cast<std::size_t>(s.settle_revolutions);
  r.x_m.reserve(steps), r.y_m.reserve(steps), r.fx_n.reserve(steps), r.fy_n.reserve(steps);
  // Each step: the displacement at its middle from the start and a look-ahead to its end with the last
  // force held, the mean force over the step from there, and the exact response to that force held
  // (second order in h; the force at the step's start alone would act half a step late).
  Eigen::Vector2d f_last = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < steps; ++k) {
    if (k == r.settle_steps) dyn.settled();
    const bool stats = k >= r.settle_steps;
    const Eigen::Vector2d q = dyn.displacement(), q_end = dyn.predict(f_last);
    const Eigen::Vector2d f = process.force(k, 0.5 * (q + q_end), stats);
    if (stats) r.peak_force_n = std::max(r.peak_force_n, f.norm());
    r.x_m.push_back(q(0)), r.y_m.push_back(q(1)), r.fx_n.push_back(f(0)), r.fy_n.push_back(f(1));
    dyn.step(f);
    f_last = f;
    process.end_step(q, dyn.displacement());
  }
  r.engaged_samples = process.engaged_samples();
  r.out_of_cut_samples = process.out_of_cut_samples();
  r.wall_per_rev_um = process.wall_per_rev_um();
  r.wall_um = process.wall_um();
  r.sle_um = process.sle_um();
  return r;
}

}  // namespace robodamp::milling
