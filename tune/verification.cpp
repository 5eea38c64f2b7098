#include "tune/verification.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"
#include "milling/lobes.hpp"

namespace robodamp::tune {

namespace {

// The damped cut's critical depth in time, with the real Controller; revolutions enough that a slow decay
// near the limit is not read as chatter.
double time_domain_mm(const config::MillingConfig& job, const milling::Structure& open, double rpm, double guess_mm) {
  milling::CutOverrides o;
  o.rpm = rpm;
  o.damped = true;
  o.revolutions = std::max(job.time_domain.revolutions, 300);
  const milling::CutJob cut = milling::make_cut_job(job, open, o);
  return milling::critical_depth(cut.dynamics, cut.cutter, cut.material, cut.settings, guess_mm, 2e-3).depth_mm;
}

}  // namespace

double time_domain_critical_mm(const config::Config& cfg, const config::MillingConfig& job, double rpm,
                               double guess_mm) {
  const auto model = std::make_shared<const analysis::LoopModel>(cfg);
  const milling::Structure open(job.selected_structure(), false,
                                {model, cfg.controller.gain_ns_per_m, cfg.controller.polarity});
  return time_domain_mm(job, open, rpm, guess_mm);
}

bool Verification::time_domain_agrees(double tolerance) const {
  return std::abs(time_domain_at_speed_mm / depth_at_speed_mm - 1.0) <= tolerance &&
         std::abs(time_domain_at_min_mm / min_depth_mm - 1.0) <= tolerance;
}

Verification verify(const config::Config& cfg, const config::MillingConfig& job_in) {
  // The job's structure with every controller part running this configuration (its file need not exist yet).
  const config::MillingConfig& job = job_in;
  const auto model = std::make_shared<const analysis::LoopModel>(cfg);
  const double k = cfg.controller.gain_ns_per_m;
  const int pol = cfg.controller.polarity;
  const config::StructureConfig& st = job.selected_structure();
  const milling::Structure open(st, false, {model, k, pol}), damped(st, true, {model, k, pol});
  const milling::AccurateStability truth(damped, job), open_truth(open, job);
  const auto process = milling::chatter_process(job.tool, job.material, job.cut);
  config::LobesConfig grid = job.lobes;
  grid.points = job.time_domain.sdm_points;
  const milling::LobeDiagram guess = milling::LobeModel(damped, process, grid).diagram();
  const milling::LobeDiagram open_guess = milling::LobeModel(open, process, grid).diagram();
  std::vector<double> speeds, guesses, open_guesses;
  for (std::size_t i = 0; i < guess.curve.size(); ++i)
    if (guess.curve[i].rpm <= truth.max_rpm())
      speeds.push_back(guess.curve[i].rpm), guesses.push_back(guess.curve[i].b_lim_mm),
          open_guesses.push_back(open_guess.curve[i].b_lim_mm);
  Verification v;
  v.method = truth.method();
  v.min_depth_mm = INFINITY;
  for (const milling::SdmPoint& p : truth.critical(speeds, guesses)) {
    v.damped_curve_mm.emplace_back(p.rpm, p.critical_depth_mm);
    if (p.critical_depth_mm < v.min_depth_mm) v.min_depth_mm = p.critical_depth_mm, v.min_rpm = p.rpm;
  }
  v.open_min_depth_mm = INFINITY;
  for (const milling::SdmPoint& p : open_truth.critical(speeds, open_guesses))
    v.open_min_depth_mm = std::min(v.open_min_depth_mm, p.critical_depth_mm);
  const milling::LobeModel zoa(damped, process, job.lobes);
  const milling::SdmPoint at = truth.critical(job.cut.spindle_rpm, zoa.critical_depth_mm(job.cut.spindle_rpm));
  v.depth_at_speed_mm = at.critical_depth_mm;
  v.speed_rpm = at.rpm;
  // The time domain closes the same parts with the real Controller running this configuration.
  v.time_domain_at_speed_mm = time_domain_mm(job, open, job.cut.spindle_rpm, v.depth_at_speed_mm);
  v.time_domain_at_min_mm = time_domain_mm(job, open, v.min_rpm, v.min_depth_mm);
  return v;
}

}  // namespace robodamp::tune
