#include "commission/command_line.hpp"

#include <cstdio>

namespace robodamp::commission {

std::string command_line(const CommissionSettings& s) {
  std::string c = "robodamp commission --config " + s.config_path + " --job " + s.job_path + " --out " + s.out_dir;
  const CommissionSettings ds;
  const tune::TuneSettings &d = ds.tune, &t = s.tune;
  char b[64];
  if (s.shift_pct) std::snprintf(b, sizeof b, " --shift-pct %g", *s.shift_pct), c += b;
  if (t.global_evaluations != d.global_evaluations) c += " --evaluations " + std::to_string(t.global_evaluations);
  if (t.local_evaluations != d.local_evaluations) c += " --polish " + std::to_string(t.local_evaluations);
  if (t.seed != d.seed) c += " --seed " + std::to_string(t.seed);
  if (s.schedule_speeds != ds.schedule_speeds) c += " --schedule-speeds " + std::to_string(s.schedule_speeds);
  if (s.schedule_gains != ds.schedule_gains) c += " --schedule-gains " + std::to_string(s.schedule_gains);
  for (const auto& tap : s.tap_tests) c += " --tap-tests " + tap;
  return c;
}

std::string command_line(const PathCommissionSettings& s) {
  std::string c = "robodamp commission --config " + s.config_path + " --job " + s.job_path + " --out " + s.out_dir +
                  " --along-path --dwells " + std::to_string(s.dwells);
  for (const auto& w : s.trajectory) c += " --pose-at " + w;
  if (!s.hold_out.empty()) {
    c += " --hold-out";
    for (const auto& h : s.hold_out) c += " " + h;
  }
  c += " --evaluations " + std::to_string(s.pose_tune.tune.global_evaluations) + " --polish " +
       std::to_string(s.pose_tune.tune.local_evaluations) + " --map-points " + std::to_string(s.map_points) +
       " --max-regions " + std::to_string(s.pose_tune.max_regions) + " --seed " + std::to_string(s.pose_tune.tune.seed);
  return c;
}

}  // namespace robodamp::commission
