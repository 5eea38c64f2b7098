#include "milling/scheduled_lobes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <set>

#include "analysis/loop_model.hpp"
#include "config/config.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/forced_command.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

std::vector<SdmPoint> scheduled_limits(const config::StructureConfig& sc, const config::MillingConfig& job,
                                       const config::Config& cell, const std::vector<double>& speeds,
                                       const std::vector<SdmPoint>& open) {
  std::vector<config::Config> sets{cell};
  if (cell.controller.speed_schedule)
    for (std::size_t i = 1; i <= cell.controller.speed_schedule->controllers.size(); ++i)
      sets.push_back(config::speed_controller_config(cell, i));
  std::map<std::pair<std::size_t, double>, std::vector<std::size_t>> groups;  // (set, K) -> speed indices
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    std::size_t set = config::scheduled_set(sets.front(), 0, speeds[i]);
    if (set >= sets.size()) set = 0;
    groups[{set, config::scheduled_gain_ns_per_m(sets[set], set, speeds[i])}].push_back(i);
  }
  std::vector<SdmPoint> out = open;
  for (const auto& [candidate, idx] : groups) {
    const auto [set, gain] = candidate;
    if (gain <= 0.0) continue;  // the damper commands nothing: the open loop
    const Structure damped(
        sc, true, {std::make_shared<const analysis::LoopModel>(sets[set]), gain, sets[set].controller.polarity});
    const AccurateStability truth(damped, job);
    std::vector<double> rpm, guess;
    for (const std::size_t i : idx) rpm.push_back(speeds[i]), guess.push_back(open[i].critical_depth_mm);
    std::vector<SdmPoint> pts = truth.critical(rpm, guess);
    std::vector<double> mm;
    for (const auto& p : pts) mm.push_back(p.critical_depth_mm);
    mm = holding_limits_mm(damped, job, rpm, mm);  // as deep as the actuator follows the forced vibration
    for (std::size_t k = 0; k < rpm.size(); ++k)   // no deeper than the band vouches for (the cut in time)
      if (const auto cap = config::scheduled_depth_limit_mm(sets[set], set, rpm[k]); cap && *cap < mm[k]) mm[k] = *cap;
    for (std::size_t k = 0; k < idx.size(); ++k) pts[k].critical_depth_mm = mm[k], out[idx[k]] = pts[k];
  }
  return out;
}

std::optional<ScheduledLobes> scheduled_lobe_study(const config::StructureConfig& sc, const config::MillingConfig& job,
                                                   const std::vector<double>& rpms,
                                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto part =
      std::find_if(sc.parts.begin(), sc.parts.end(), [](const auto& p) { return p.controller.has_value(); });
  if (part == sc.parts.end()) return std::nullopt;
  const config::Config cell = config::load_config_file(part->controller->config_path);
  if (!cell.controller.speed_schedule) return std::nullopt;
  const auto t0 = std::chrono::steady_clock::now();
  const auto model = std::make_shared<const analysis::LoopModel>(cell);
  const Structure open(sc, false, {model, 0.0, cell.controller.polarity});
  const Structure stepper(sc, true, {model, 1.0, cell.controller.polarity});  // the sampled loop's speeds
  const AccurateStability step(stepper, job), open_truth(open, job);
  const int n = job.time_domain.sdm_points;
  const double lo = job.lobes.rpm_min, hi = std::min(job.lobes.rpm_max, step.max_rpm());
  std::set<double> grid;
  for (int i = 0; i < n; ++i) grid.insert(step.stepped_rpm(lo + (hi - lo) * i / std::max(1, n - 1)));
  std::vector<double> speeds(grid.begin(), grid.end());
  for (const double r : rpms) speeds.push_back(step.stepped_rpm(r));
  const LobeModel zoa(open, chatter_process(job.tool, job.material, job.cut), job.lobes);
  std::vector<double> guess;
  for (const double r : speeds) {
    const auto z = zoa.limit_at(r);
    guess.push_back(z && std::isfinite(z->b_lim_mm) ? z->b_lim_mm : job.cut.axial_mm);
  }
  const std::vector<SdmPoint> o = open_truth.critical(speeds, guess, 0, 1e-3, [&](std::size_t done) {
    if (progress) progress(done, 2 * speeds.size());
  });
  const std::vector<SdmPoint> s = scheduled_limits(sc, job, cell, speeds, o);
  if (progress) progress(2 * speeds.size(), 2 * speeds.size());
  ScheduledLobes out;
  out.config = cell.source;
  out.bands = cell.controller.speed_schedule->bands.size();
  LobeStudy& st = out.study;
  st.structure = open.name();
  st.closed_loop = true;
  st.method = "sampled-loop SDM, speed schedule";
  st.accurate = true;
  st.steps_per_period = step.grid_per_period();
  st.min_b_lim_mm = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < grid.size(); ++i) {
    st.curve.push_back({s[i].rpm, s[i].critical_depth_mm, s[i].chatter_hz, std::nullopt, to_string(s[i].type)});
    out.open_mm.push_back(o[i].critical_depth_mm);
    if (s[i].critical_depth_mm < o[i].critical_depth_mm * 0.995) ++out.below_open;
    if (s[i].critical_depth_mm < st.min_b_lim_mm)
      st.min_b_lim_mm = s[i].critical_depth_mm, st.min_rpm = s[i].rpm, st.min_chatter_hz = s[i].chatter_hz;
  }
  for (std::size_t k = 0; k < rpms.size(); ++k) {
    const SdmPoint& p = s[grid.size() + k];
    LobeAtSpeed a;
    a.rpm = p.rpm;
    a.requested_rpm = rpms[k];
    a.b_lim_mm = p.critical_depth_mm;
    a.chatter_hz = p.chatter_hz;
    a.type = to_string(p.type);
    st.at_rpm.push_back(a);
  }
  st.diagram_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  st.notes.push_back(cell.source + "'s speed schedule: " + std::to_string(out.bands) +
                     " bands, each speed with its band's "
                     "controller and K (K = 0: the open loop's SDM there)");
  return out;
}

}  // namespace robodamp::milling
