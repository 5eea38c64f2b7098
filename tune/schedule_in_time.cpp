#include "tune/schedule_in_time.hpp"

#include <algorithm>
#include <functional>

#include "analysis/task_pool.hpp"
#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"

namespace robodamp::tune {

namespace {

LimitInTimeResult check(const config::MillingConfig& job, const LimitInTime& c, double fraction) {
  milling::CutOverrides o;
  o.rpm = c.rpm;
  o.damped = true;
  o.axial_mm = fraction * c.limit_mm;
  const milling::CutJob cut = milling::make_cut_job(job, *c.structure, o);
  LimitInTimeResult r;
  r.limit_mm = c.limit_mm;
  r.simulations = 1;
  if (milling::run_job(cut).verdict.stable) return r;
  r.held = false;
  const milling::CriticalDepth td =
      milling::critical_depth(cut.dynamics, cut.cutter, cut.material, cut.settings, fraction * c.limit_mm, 2e-3);
  r.limit_mm = std::min(c.limit_mm, td.depth_mm);
  r.simulations += td.simulations;
  return r;
}

}  // namespace

std::vector<LimitInTimeResult> limits_in_time(const config::MillingConfig& job, const std::vector<LimitInTime>& checks,
                                              std::size_t threads, double fraction) {
  std::vector<LimitInTimeResult> out(checks.size());
  std::vector<std::function<void()>> tasks;
  for (std::size_t i = 0; i < checks.size(); ++i)
    tasks.emplace_back([&, i] { out[i] = check(job, checks[i], fraction); });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  return out;
}

}  // namespace robodamp::tune
