#include "tune/pose_tune_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "tune/tuned_file.hpp"

namespace robodamp::tune {

namespace {

using nlohmann::json;

std::string pct(double v) {
  if (std::isinf(v)) return v < 0 ? "unstable" : "-";
  char b[24];
  std::snprintf(b, sizeof b, "%+.1f", v);
  return b;
}

json region_json(const TunedRegion& r) {
  return {{"name", r.region.name},
          {"min_deg", r.region.min_deg},
          {"max_deg", r.region.max_deg},
          {"poses", r.poses.size()},
          {"dominant_min_hz", r.dominant_min_hz},
          {"dominant_max_hz", r.dominant_max_hz},
          {"gain_ns_per_m", *r.region.gain_ns_per_m},
          {"polarity", *r.region.polarity},
          {"match_freq_hz", *r.region.match_freq_hz},
          {"gain_margin_db", r.worst.gain_margin_db},
          {"phase_margin_deg", r.worst.phase_margin_deg},
          {"worst_mode_improvement_pct", r.worst.worst_mode_improvement_pct},
          {"serves", r.serves()},
          {"binding", r.worst.binding}};
}

void print_regions(std::ostringstream& t, const char* what, const std::vector<TunedRegion>& rs) {
  char b[320];
  t << what << '\n';
  t << "  region      joints from / to deg                            poses  dominant Hz    K N s/m  pol  GM dB  PM "
       "deg  worst mode %  serves\n";
  for (const auto& r : rs) {
    std::snprintf(b, sizeof b, "  %-10s  %-22s %-22s  %5zu  %5.2f-%-5.2f  %9.0f  %+3d  %5.1f  %6.1f  %12s  %s\n",
                  r.region.name.c_str(), config::describe_pose(r.region.min_deg).c_str(),
                  config::describe_pose(r.region.max_deg).c_str(), r.poses.size(), r.dominant_min_hz, r.dominant_max_hz,
                  *r.region.gain_ns_per_m, *r.region.polarity, r.worst.gain_margin_db, r.worst.phase_margin_deg,
                  pct(r.worst.worst_mode_improvement_pct).c_str(),
                  r.serves() ? "yes" : ("no: " + r.worst.binding).c_str());
    t << b;
  }
}

json print_map(std::ostringstream& t, const MapScores& s) {
  char b[320];
  json rows = json::array();
  t << "the workspace map (" << s.map.size() << " poses; worst mode and driving point in %"
    << (s.method.empty() ? "" : ", the job's smallest limiting depth in mm by " + s.method) << "):\n";
  t << "  pose                          role       dominant Hz   open mm";
  for (const auto& c : s.controllers) t << "  | " << c.name << ": mode %  point %  damped mm";
  t << '\n';
  for (std::size_t i = 0; i < s.map.size(); ++i) {
    const MapPose& m = s.map[i];
    std::snprintf(b, sizeof b, "  %-29s %-9s  %10.2f  %8s", m.pose.name.c_str(), m.role.c_str(), m.dominant_hz,
                  m.open_min_mm ? exact(std::round(*m.open_min_mm * 1e4) / 1e4).c_str() : "-");
    t << b;
    json row = {
        {"pose", m.pose.name}, {"joints_deg", m.pose.joints_deg}, {"role", m.role}, {"dominant_hz", m.dominant_hz}};
    if (m.open_min_mm) row["open_min_mm"] = *m.open_min_mm;
    for (const auto& c : s.controllers) {
      const PoseScore& p = c.poses[i];
      std::snprintf(b, sizeof b, "  | %*s%8s %8s %10s", static_cast<int>(c.name.size()) - 4, "",
                    p.regions.empty() ? "outside" : pct(p.worst_mode_improvement_pct).c_str(),
                    pct(p.improvement_pct).c_str(),
                    p.damped_min_mm ? exact(std::round(*p.damped_min_mm * 1e4) / 1e4).c_str() : "-");
      t << b;
      json pj = {{"regions", p.regions}, {"stable", p.stable}};
      if (!p.regions.empty() && p.stable) {
        pj["worst_mode_improvement_pct"] = p.worst_mode_improvement_pct, pj["improvement_pct"] = p.improvement_pct;
        json by = json::object();  // the set that runs depends on the path (the hand-over's hysteresis)
        for (std::size_t r = 0; r < p.regions.size(); ++r) by[p.regions[r]] = p.region_improvement_pct[r];
        pj["improvement_by_region_pct"] = by;
      }
      if (p.damped_min_mm) pj["damped_min_mm"] = *p.damped_min_mm, pj["damped_min_rpm"] = *p.damped_min_rpm;
      row[c.name] = pj;
    }
    t << '\n';
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

PoseTuneReport pose_tune_report(const std::string& config_path, const PoseTuneInput& in, std::size_t held_out,
                                const WorkspaceTune& w, const PoseTuneSettings& s,
                                const std::optional<config::MillingConfig>& job, const std::string& job_path) {
  const TunedRegion& robust = w.robust;
  const std::vector<TunedRegion>& scheduled = w.scheduled;
  const MapScores& scores = w.scores;
  const std::size_t best = w.best;
  std::ostringstream t;
  t << "robodamp pose tune: " << config_path << ", the robot " << in.model.name << " (" << in.model.source << "), "
    << in.measured.size() << " measured pose(s) tuned at, " << held_out << " held out; the damping band "
    << config::format_number(in.cell.pose_schedule->damping_band_min_hz) << "-"
    << config::format_number(in.cell.pose_schedule->damping_band_max_hz)
    << " Hz (a set serves while no mode in it is more than " << config::format_number(s.worse_mode_tolerance_pct)
    << " % worse than open loop: --worse-mode-pct)\n";
  print_regions(t, "robust: one set over the workspace", {robust});
  print_regions(
      t, ("scheduled: " + std::to_string(scheduled.size()) + " region(s) drawn where one set stops serving").c_str(),
      scheduled);
  json map = print_map(t, scores);
  json summary = json::array();
  for (const auto& c : scores.controllers) {
    t << "  " << c.name << ": " << (c.stable_everywhere ? "stable at every pose" : "UNSTABLE at a pose")
      << ", worst mode in the damping band " << pct(c.worst_mode_improvement_pct) << " %";
    if (c.outside_band_pct)
      t << " (outside it " << pct(*c.outside_band_pct) << " % at "
        << config::format_number(std::round(*c.outside_band_hz * 100) / 100) << " Hz)";
    t << ", worst driving point " << pct(c.worst_improvement_pct) << " %";
    if (c.damped_min_mm)
      t << ", the job's smallest damped depth " << *c.damped_min_mm << " mm (" << scores.method << ")";
    t << '\n';
    json cj = {
        {"name", c.name},
        {"stable_everywhere", c.stable_everywhere},
        {"worst_mode_improvement_pct", c.stable_everywhere ? json(c.worst_mode_improvement_pct) : json(nullptr)},
        {"outside_band_pct", c.stable_everywhere && c.outside_band_pct ? json(*c.outside_band_pct) : json(nullptr)}};
    if (c.damped_min_mm) cj["damped_min_mm"] = *c.damped_min_mm;
    summary.push_back(cj);
  }
  t << "chosen: " << scores.controllers[best].name << '\n';
  if (const double worst = scores.controllers[best].worst_mode_improvement_pct; worst < 0.0)
    t << "  note: a mode in the damping band ends " << pct(worst) << " % against open loop at a map pose, worse ("
      << (worst >= -s.worse_mode_tolerance_pct ? "within" : "BEYOND") << " --worse-mode-pct "
      << config::format_number(s.worse_mode_tolerance_pct) << ")\n";
  json regions_robust = json::array({region_json(robust)}), regions_sched = json::array();
  for (const auto& r : scheduled) regions_sched.push_back(region_json(r));
  PoseTuneReport out;
  out.json = {{"config", config_path},
              {"model", in.model.source},
              {"robust", regions_robust},
              {"scheduled", regions_sched},
              {"map", map},
              {"controllers", summary},
              {"chosen", scores.controllers[best].name},
              {"model_of_promises", "the pose-indexed robot model, discrete loop"},
              {"worse_mode_pct", s.worse_mode_tolerance_pct}};
  if (job) out.json["method"] = scores.method, out.json["job"] = job_path;
  out.text = t.str();
  return out;
}

}  // namespace robodamp::tune
