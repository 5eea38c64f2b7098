#include "apps/pose_tune_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>
#include "identify/pose_measurements.hpp"
#include "tune/pose_score.hpp"
#include "tune/pose_tune.hpp"
#include "tune/pose_tune_file.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;
using tune::exact;

std::string pct(double v) {
  if (std::isinf(v)) return v < 0 ? "unstable" : "-";
  char b[24];
  std::snprintf(b, sizeof b, "%+.1f", v);
  return b;
}

// The measured poses (fit) and the held-out ones, by name; refused where they contradict each other under
// the model (identify::check_against_model).
void read_poses(const PoseTuneArgs& a, const config::RobotModelConfig& model, std::vector<tune::NamedPose>& measured,
                std::vector<tune::NamedPose>& held) {
  if (a.measurements.empty()) return;
  const identify::PoseMeasurements pm = identify::read_pose_measurements(a.measurements);
  identify::check_against_model(pm, model);
  for (const auto& f : pm.frfs) measured.push_back({f.name, f.joints_deg});
  for (const std::string& name : a.hold_out) {
    const auto it = std::find_if(measured.begin(), measured.end(), [&](const auto& p) { return p.name == name; });
    if (it == measured.end()) throw std::invalid_argument("--hold-out '" + name + "': no measured pose of that name");
    held.push_back(*it);
    measured.erase(it);
  }
}

// The command that reproduces the file (its header).
std::string command_line(const PoseTuneArgs& a) {
  std::string c = "robodamp pose tune --config " + a.config_path;
  if (!a.model_path.empty()) c += " --model " + a.model_path;
  if (!a.measurements.empty()) {
    c += " --measurements";
    for (const auto& m : a.measurements) c += " " + m;
  }
  if (!a.hold_out.empty()) {
    c += " --hold-out";
    for (const auto& h : a.hold_out) c += " " + h;
  }
  if (!a.job_path.empty()) c += " --job " + a.job_path;
  c += " --evaluations " + std::to_string(a.evaluations) + " --polish " + std::to_string(a.polish) + " --max-regions " +
       std::to_string(a.max_regions) + " --map-points " + std::to_string(a.map_points) + " --overlap-deg " +
       config::format_number(a.overlap_deg) + " --worse-mode-pct " + config::format_number(a.worse_mode_pct) +
       " --seed " + std::to_string(a.seed) + " --out " + a.out_path;
  return c;
}

json region_json(const tune::TunedRegion& r) {
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

void print_regions(std::ostringstream& t, const char* what, const std::vector<tune::TunedRegion>& rs) {
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

json print_map(std::ostringstream& t, const tune::MapScores& s) {
  char b[320];
  json rows = json::array();
  t << "the workspace map (" << s.map.size() << " poses; worst mode and driving point in %"
    << (s.method.empty() ? "" : ", the job's smallest limiting depth in mm by " + s.method) << "):\n";
  t << "  pose                          role       dominant Hz   open mm";
  for (const auto& c : s.controllers) t << "  | " << c.name << ": mode %  point %  damped mm";
  t << '\n';
  for (std::size_t i = 0; i < s.map.size(); ++i) {
    const tune::MapPose& m = s.map[i];
    std::snprintf(b, sizeof b, "  %-29s %-9s  %10.2f  %8s", m.pose.name.c_str(), m.role.c_str(), m.dominant_hz,
                  m.open_min_mm ? exact(std::round(*m.open_min_mm * 1e4) / 1e4).c_str() : "-");
    t << b;
    json row = {
        {"pose", m.pose.name}, {"joints_deg", m.pose.joints_deg}, {"role", m.role}, {"dominant_hz", m.dominant_hz}};
    if (m.open_min_mm) row["open_min_mm"] = *m.open_min_mm;
    for (const auto& c : s.controllers) {
      const tune::PoseScore& p = c.poses[i];
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

// long: the command's steps in order (read, tune both, score, choose, write, report); each is a call
int run_pose_tune(const PoseTuneArgs& a) {
  try {
    if (a.config_path.empty()) throw std::invalid_argument("give --config: a configuration with a pose_schedule");
    tune::PoseTuneInput in{config::load_config_file(a.config_path), {}, {}};
    if (!in.cell.pose_schedule)
      throw std::invalid_argument("--config " + a.config_path +
                                  " has no pose_schedule (its model, axis and workspace)");
    in.model = config::load_robot_model(a.model_path.empty() ? in.cell.pose_schedule->model_resolved : a.model_path);
    std::vector<tune::NamedPose> held;
    read_poses(a, in.model, in.measured, held);
    std::optional<config::MillingConfig> job;
    if (!a.job_path.empty()) job = config::load_milling_config(a.job_path);
    tune::PoseTuneSettings s;
    s.tune.global_evaluations = a.evaluations, s.tune.local_evaluations = a.polish, s.tune.seed = a.seed;
    s.max_regions = a.max_regions, s.overlap_deg = a.overlap_deg, s.worse_mode_tolerance_pct = a.worse_mode_pct;
    const auto progress = [](const std::string& m) { std::cerr << "robodamp pose tune: " << m << '\n'; };
    const tune::WorkspaceTune w = tune::tune_workspace(in, held, job, s, a.map_points, progress);
    const tune::TunedRegion& robust = w.robust;
    const std::vector<tune::TunedRegion>& scheduled = w.scheduled;
    const tune::MapScores& scores = w.scores;
    const std::size_t best = w.best;
    std::ostringstream t;
    t << "robodamp pose tune: " << a.config_path << ", the robot " << in.model.name << " (" << in.model.source << "), "
      << in.measured.size() << " measured pose(s) tuned at, " << held.size() << " held out; the damping band "
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
    json out = {{"config", a.config_path},
                {"model", in.model.source},
                {"robust", regions_robust},
                {"scheduled", regions_sched},
                {"map", map},
                {"controllers", summary},
                {"chosen", scores.controllers[best].name},
                {"model_of_promises", "the pose-indexed robot model, discrete loop"},
                {"worse_mode_pct", s.worse_mode_tolerance_pct}};
    if (job) out["method"] = scores.method, out["job"] = a.job_path;
    if (!scores.controllers[best].stable_everywhere) {
      std::cerr << t.str() << "robodamp pose tune: no controller is stable at every pose of the map; nothing written\n";
      return 1;
    }
    if (!a.out_path.empty()) {
      const std::string header =
          "# robodamp pose tune: the " + scores.controllers[best].name + " controller over the workspace of " +
          a.config_path + ", written by\n#   " + command_line(a) +
          "\n# (the comparison of the robust, the scheduled and the given controllers: the same with --json)\n";
      (void)tune::write_pose_tuned_config(in.cell, w.chosen(), a.model_path, a.out_path, header);
      t << "wrote " << a.out_path << " (read back, every region's set analysed over its grid)\n";
      out["out"] = a.out_path;
    }
    if (!emit_json(a.json, out.dump(2), "pose tune")) return 1;
    (a.json.to_stdout() ? std::cerr : std::cout) << t.str();
    return 0;
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp pose tune: " << e.what() << '\n';
    return 2;
  }
}

}  // namespace robodamp::apps
