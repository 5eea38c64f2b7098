#include "commission/path_commission.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "analysis/pose_schedule.hpp"
#include "commission/emulated_cell.hpp"
#include "commission/path_report.hpp"
#include "commission/stage_detail.hpp"
#include "config/file_paths.hpp"
#include "config/yaml_edit.hpp"
#include "hil/pose_trajectory.hpp"
#include "identify/commissioning.hpp"
#include "identify/pose_measurements.hpp"
#include "identify/pose_modes.hpp"
#include "milling/live_stability.hpp"
#include "tune/never_worse.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::commission {

bool PathStop::improvement_held(double tolerance_points, double peak_tolerance, double sigmas) const {
  const double off = std::abs(measured_improvement_pct - predicted_improvement_pct);
  return on_cell && records >= 2 &&
         (off <= tolerance_points || std::abs(peak_error()) <= peak_tolerance || off <= sigmas * predicted_sigma_pct);
}

namespace {

namespace fs = std::filesystem;
using detail::Clock;
using detail::fmt;
using detail::seconds_since;
using detail::Stop;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool same_pose(const std::vector<double>& a, const std::vector<double>& b, double tol_deg) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!(std::abs(a[i] - b[i]) <= tol_deg)) return false;
  return true;
}

// The trajectory's waypoints, in time order (the emulator's --pose-at syntax). Throws std::invalid_argument.
std::vector<hil::PoseWaypoint> waypoints(const std::vector<std::string>& items) {
  std::vector<hil::PoseWaypoint> out;
  for (const auto& item : items) {
    hil::PoseWaypoint w;
    std::string error;
    if (!hil::parse_waypoint(item, w, error)) throw std::invalid_argument("--pose-at = " + item + ": " + error);
    if (!out.empty() && !(w.t_s > out.back().t_s))
      throw std::invalid_argument("--pose-at = " + item + ": its time is not after the previous waypoint's");
    out.push_back(std::move(w));
  }
  return out;
}

// The set that runs at each pose the robot stops at, as the supervisor picks it along the path: the current
// region while the pose stays inside it (the overlap's hysteresis), else the first that holds it. Each
// segment between waypoints is walked in small steps (the robot moves in a straight line in joint space).
std::vector<std::optional<std::size_t>> regions_along(const config::PoseScheduleConfig& s,
                                                      const std::vector<hil::PoseWaypoint>& path,
                                                      const std::vector<std::vector<double>>& stops) {
  std::vector<std::optional<std::size_t>> out(stops.size());
  if (path.empty()) return out;
  std::optional<std::size_t> current =
      config::region_of(s, path.front().joints_deg.data(), path.front().joints_deg.size());
  const auto note = [&](const std::vector<double>& q) {
    for (std::size_t i = 0; i < stops.size(); ++i)
      if (!out[i] && same_pose(q, stops[i], 0.05)) out[i] = current;
  };
  note(path.front().joints_deg);
  for (std::size_t w = 1; w < path.size(); ++w) {
    const auto& a = path[w - 1].joints_deg;
    const auto& b = path[w].joints_deg;
    constexpr int kSteps = 200;
    std::vector<double> q(a.size());
    for (int k = 1; k <= kSteps; ++k) {
      for (std::size_t j = 0; j < q.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / kSteps;
      current = config::region_of(s, q.data(), q.size(), current);
    }
    note(b);
  }
  return out;
}

// The path again for the verification, each stop held only as long as its impacts need (hil.settle_s, then
// `records` of bench.record_s, the emulator's dwell campaign), the moves as they were: the same poses and
// hand-overs in a fraction of the measurement's time.
std::vector<hil::PoseWaypoint> shortened(const std::vector<hil::PoseWaypoint>& path, double dwell_s) {
  std::vector<hil::PoseWaypoint> out;
  double shift_s = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0 && path[i].joints_deg == path[i - 1].joints_deg) {
      const double held_s = path[i].t_s - path[i - 1].t_s;
      shift_s += std::max(0.0, held_s - dwell_s);
    }
    out.push_back({path[i].t_s - shift_s, path[i].joints_deg});
  }
  return out;
}

std::vector<std::string> waypoint_texts(const std::vector<hil::PoseWaypoint>& path) {
  std::vector<std::string> out;
  for (const auto& w : path) {
    std::string t = config::format_number(w.t_s) + ":";
    for (std::size_t j = 0; j < w.joints_deg.size(); ++j) {
      if (j > 0) t += ',';  // not (j ? "," : "") + a string: GCC 12's false -Wrestrict on that concatenation
      t += config::format_number(w.joints_deg[j]);
    }
    out.push_back(t);
  }
  return out;
}

class PathRun {
 public:
  PathRun(const PathCommissionSettings& s, const std::function<void(const std::string&)>& progress,
          PathCommissionResult& r)
      : s_(s), say_(progress), r_(r), dir_(s.out_dir), stage_(s.from, s.out_dir, say_, r.stage, r.times) {}

  void all() {
    fs::create_directories(dir_);
    std::error_code ec;
    fs::remove(dir_ / "configuration.yaml", ec);  // only this run's verified result may stand there
    cell_ = config::load_config_file(s_.config_path);
    if (!cell_.pose_schedule)
      throw Stop{Stage::kMeasure, Outcome::kBadInput,
                 s_.config_path +
                     " has no pose_schedule: along the path robodamp schedules the controller by pose "
                     "(its model is the prior between the stops)"};
    if (!cell_.can || cell_.can->interface.rfind("unix:", 0) != 0)
      throw Stop{
          Stage::kMeasure, Outcome::kBadInput,
          "along the path robodamp's hammer hits at each stop, and only the HIL emulator (can.interface unix:...) "
          "has one; on a real cell measure with `robodamp measure --along-path --no-hammer`, tap at each stop "
          "with your modal kit and map the modes with `robodamp pose modes`"};
    if (s_.trajectory.empty())
      throw Stop{Stage::kMeasure, Outcome::kBadInput,
                 "give the robot's path in the emulator: --pose-at T:Q1,Q2,... (the robot program's waypoints, as "
                 "robodamp plant takes them)"};
    path_ = waypoints(s_.trajectory);
    binary_ = s_.robodamp_binary.empty() ? this_executable() : s_.robodamp_binary;
    job_ = config::load_milling_config(s_.job_path);
    r_.job_rpm = job_.cut.spindle_rpm;
    say_("commission: along the path through the HIL emulator on " + cell_.can->interface + ": " +
         std::to_string(s_.dwells) + " stops, " + std::to_string(s_.hold_out.size()) + " held out of the map");
    stage_(Stage::kMeasure, [this] { measure(); });
    stage_(Stage::kIdentify, [this] { identify(); });
    stage_(Stage::kTune, [this] { tune(); });
    stage_(Stage::kVerify, [this] { verify(); });
    stage_(Stage::kWrite, [this] { write(); });
  }

 private:
  void measure() {
    if (stage_.reuse()) {
      if (!fs::exists(dir_ / "measurement" / "poses.json"))
        throw Stop{Stage::kMeasure, Outcome::kBadInput,
                   "--from " + std::string(to_string(s_.from)) + ": " + (dir_ / "measurement" / "poses.json").string() +
                       " does not exist: run from measure"};
      return;
    }
    PathMeasureOptions po;
    po.measure.impacts = true;
    po.dwells = s_.dwells;
    po.max_run_s = s_.max_run_s;
    po.still_deg = s_.still_deg;
    const PathMeasureOutcome o = measure_along_path_through_emulator(
        cell_, s_.config_path, (dir_ / "measurement").string(), binary_, s_.trajectory, po);
    std::signal(SIGINT, SIG_DFL);  // the measurement's loop turned them into a trip; no loop runs now
    std::signal(SIGTERM, SIG_DFL);
    for (const auto& d : o.dwells)
      say_("commission:   " + d.name + " at " + config::describe_pose(d.joints_deg) +
           (d.measured ? fmt(": measured (the chirp %.1f-%.1f s)", d.chirp_start_s, d.chirp_end_s)
                       : ": not measured: " + d.skipped));
    detail::throw_unless_measured(o.run, Stage::kMeasure);
    if (o.measured() < s_.dwells)
      throw Stop{Stage::kMeasure, Outcome::kFailed,
                 fmt("%d of %d stops measured: the robot stopped too few times, or too briefly, within the run",
                     o.measured(), s_.dwells)};
  }

  // Each stop on its own, then the map between them; the tune's base: the cell with the actuator identified.
  void identify() {
    const identify::PoseMeasurements pm = identify::read_pose_measurements({(dir_ / "measurement").string()});
    identify::CommissioningSettings cs;
    std::vector<identify::ActuatorFit> acts;
    for (std::size_t i = 0; i < pm.frfs.size(); ++i) {
      const identify::CommissioningResult id = identify::identify_all(pm.dirs[i], cs);
      PathStop st;
      st.name = pm.frfs[i].name;
      st.joints_deg = pm.frfs[i].joints_deg;
      st.held_out = std::find(s_.hold_out.begin(), s_.hold_out.end(), st.name) != s_.hold_out.end();
      st.actuator_hz = id.actuator.natural_freq_hz;
      acts.push_back(id.actuator);
      r_.stops.push_back(st);
      say_(fmt("commission:   %s at %s: actuator %.3f N/V, %.3f Hz, zeta %.4f, delay %.3f ms; dominant mode %.2f Hz%s",
               st.name.c_str(), config::describe_pose(st.joints_deg).c_str(), id.actuator.force_constant_n_per_v,
               id.actuator.natural_freq_hz, id.actuator.damping_ratio, id.actuator.delay_ms, id.dominant_mode_hz,
               st.held_out ? " (held out of the map)" : ""));
    }
    if (acts.empty()) throw Stop{Stage::kIdentify, Outcome::kFailed, "no stop was measured"};
    std::vector<double> f_hz;
    for (const auto& a : acts) f_hz.push_back(a.natural_freq_hz);
    r_.actuator_spread_pct =
        100.0 * (*std::max_element(f_hz.begin(), f_hz.end()) - *std::min_element(f_hz.begin(), f_hz.end())) /
        median(f_hz);
    map(pm);
    write_identified_cell(acts);
  }

  void map(const identify::PoseMeasurements& pm) {
    config::RobotModelConfig prior = config::load_robot_model(cell_.pose_schedule->model_resolved);
    prior.measured_modes.reset();
    identify::check_against_model(pm, prior);
    const identify::PoseModesIdentified id = identify::identify_pose_modes(pm, s_.hold_out);
    mapped_ = prior;
    mapped_.measured_modes = id.measured;
    r_.mapped_model_path = fs::absolute(dir_ / "mapped_robot.yaml").string();
    std::ofstream(r_.mapped_model_path) << "# robodamp commission --along-path: " << prior.source
                                        << " with the modes measured at each stop (robodamp pose modes)\n"
                                        << config::robot_model_yaml(mapped_);
    const int axis = id.measured.axis, count = pm.modes > 0 ? pm.modes : cell_.pose_schedule->modes;
    r_.map_rows = analysis::check_pose_modes(prior, mapped_, id.measured.poses, false, axis, count);
    for (auto& row : analysis::check_pose_modes(prior, mapped_, id.held_out, true, axis, count)) {
      if (std::isfinite(row.mapped_hz))
        r_.held_out_worst_freq_error_pct =
            std::max(r_.held_out_worst_freq_error_pct, std::abs(100.0 * (row.mapped_hz / row.measured_hz - 1.0)));
      else
        ++r_.held_out_modes_missed;
      r_.map_rows.push_back(std::move(row));
    }
    say_(fmt("commission: the modes of %zu stops mapped (%s, the model the prior between them)",
             id.measured.poses.size(), r_.mapped_model_path.c_str()) +
         (id.held_out.empty() ? std::string()
                              : fmt("; at the %zu held out the largest frequency error %.2f %%, %d mode(s) missed",
                                    id.held_out.size(), r_.held_out_worst_freq_error_pct, r_.held_out_modes_missed)));
    if (r_.held_out_modes_missed > 0 || r_.held_out_worst_freq_error_pct > s_.held_out_freq_tolerance_pct)
      throw Stop{Stage::kIdentify, Outcome::kNotVerified,
                 fmt("the map misses a stop held out of it (the largest frequency error %.2f %%, allowed %.1f %%; %d "
                     "mode(s) with "
                     "no mapped mode within 25 %%): measure more stops, closer together",
                     r_.held_out_worst_freq_error_pct, s_.held_out_freq_tolerance_pct, r_.held_out_modes_missed)};
  }

  // The cell as configured with the actuator identified (the median over the stops: it does not move with the
  // pose) and the mapped model as its pose_schedule.model.
  void write_identified_cell(const std::vector<identify::ActuatorFit>& acts) {
    const auto med = [&](auto field) {
      std::vector<double> v;
      for (const auto& a : acts) v.push_back(field(a));
      return tune::exact(median(v));
    };
    const std::vector<config::YamlEdit> edits{{{"actuator", "constant_n_per_v"},
                                               YAML::Node(med([](const auto& a) { return a.force_constant_n_per_v; })),
                                               "identified along the path"},
                                              {{"actuator", "natural_freq_hz"},
                                               YAML::Node(med([](const auto& a) { return a.natural_freq_hz; })),
                                               "identified along the path"},
                                              {{"actuator", "damping_ratio"},
                                               YAML::Node(med([](const auto& a) { return a.damping_ratio; })),
                                               "identified along the path"},
                                              {{"actuator", "delay_s"},
                                               YAML::Node(med([](const auto& a) { return a.delay_ms * 1e-3; })),
                                               "identified along the path"},
                                              {{"pose_schedule", "model"},
                                               YAML::Node(r_.mapped_model_path),
                                               "the model with the modes measured along the path"}};
    const fs::path out = dir_ / "identified.yaml";
    const std::string text =
        "# robodamp commission --along-path: " + s_.config_path + " with what the stops identified\n" +
        config::rebase_file_paths(config::edit_yaml(cell_.yaml_text, edits).text, cell_.source, out.string()).text;
    identified_ = config::parse_config(text, out.string());
    std::ofstream(out) << text;
  }

  void tune() {
    if (stage_.reuse()) {
      if (!fs::exists(dir_ / "tuned.yaml"))
        throw Stop{Stage::kTune, Outcome::kBadInput,
                   "--from verify: " + (dir_ / "tuned.yaml").string() + " does not exist: run from tune"};
      r_.chosen = "reused from " + (dir_ / "tuned.yaml").string();
      return;
    }
    tune::PoseTuneInput in{identified_, mapped_, {}};
    std::vector<tune::NamedPose> held;
    for (const auto& st : r_.stops) (st.held_out ? held : in.measured).push_back({st.name, st.joints_deg});
    const auto progress = [this](const std::string& m) { say_("commission: " + m); };
    r_.tuned = tune::tune_workspace(in, held, job_, s_.pose_tune, s_.map_points, progress);
    const tune::WorkspaceTune& w = *r_.tuned;
    r_.chosen = w.best_score().name;
    r_.method = w.scores.method;
    for (const auto& c : w.scores.controllers)
      say_("commission: " + c.name + ": " +
           (c.stable_everywhere ? "stable at every map pose" : "UNSTABLE at a map pose") +
           fmt(", worst mode in the damping band %+.1f %%, worst driving point %+.1f %%", c.worst_mode_improvement_pct,
               c.worst_improvement_pct) +
           (c.damped_min_mm ? fmt(", the job's smallest damped depth %.4f mm", *c.damped_min_mm) : std::string()));
    if (!w.best_score().stable_everywhere)
      throw Stop{Stage::kTune, Outcome::kNotVerified, "no controller is stable at every pose of the workspace map"};
    const std::string header = "# robodamp commission --along-path tuned this (the " + r_.chosen +
                               " controller) from " + std::to_string(in.measured.size()) + " stops' modes:\n#   " +
                               s_.command_line + "\n";
    const std::string tuned_path = (dir_ / "tuned.yaml").string();
    (void)tune::write_pose_tuned_config(identified_, w.chosen(), "", tuned_path, header);
    say_("commission: chose the " + r_.chosen + " controller (" +
         std::to_string(w.chosen().empty() ? identified_.pose_schedule->regions.size() : w.chosen().size()) +
         " region(s))");
    std::vector<std::vector<double>> poses;
    for (const auto& m : w.scores.map) poses.push_back(m.pose.joints_deg);
    never_worse(tuned_path, poses);
  }

  // Never worse than no damper at the job's speed, pose by pose (tune/never_worse.hpp): where a set makes the
  // job's cut shallower than the open loop, the damper is off there; the rest of its region keeps it.
  void never_worse(const std::string& tuned_path, std::vector<std::vector<double>> poses) {
    for (const auto& st : r_.stops) poses.push_back(st.joints_deg);
    const config::Config tuned = config::load_config_file(tuned_path);
    const tune::NeverWorse nw = tune::never_worse_at_speed(tuned, job_, r_.job_rpm, poses);
    for (const auto& n : nw.notes) say_("commission: " + n);
    r_.lowered = nw.notes;
    if (!nw.changed()) return;
    (void)tune::write_pose_regions(
        tuned, nw.regions, "", tuned_path,
        "# robodamp commission --along-path: the damper off where its set makes the job's cut worse "
        "(tune/never_worse.hpp)\n");
  }

  void verify() {
    tuned_ = config::load_config_file((dir_ / "tuned.yaml").string());
    const analysis::PoseScheduleAnalysis sched = analysis::analyse_pose_schedule(tuned_);
    const config::PoseScheduleConfig& ps = *tuned_.pose_schedule;
    std::vector<std::vector<double>> stop_poses;
    for (const auto& st : r_.stops) stop_poses.push_back(st.joints_deg);
    const std::vector<std::optional<std::size_t>> ran = regions_along(ps, path_, stop_poses);
    constexpr int kRecords = 3;  // per stop, as the emulator's dwell campaign averages them
    const std::vector<hil::PoseWaypoint> path =
        shortened(path_, tuned_.hil.settle_s + (kRecords + 0.5) * tuned_.bench.record_s);
    say_(fmt(
        "commission: the controller along the same path, each stop held %.0f s (hil.settle_s, then %d impact records), "
        "%.0f s in all",
        tuned_.hil.settle_s + (kRecords + 0.5) * tuned_.bench.record_s, kRecords, path.back().t_s));
    const EmulatedPathRun run = run_along_path_through_emulator(tuned_, s_.config_path, binary_, waypoint_texts(path),
                                                                path.back().t_s, (dir_ / "verify").string());
    r_.trip = run.trip, r_.pose_out_of_map = run.pose_out_of_map, r_.saturated_ticks = run.saturated_ticks;
    std::vector<config::Config> sets;
    for (const auto& rs : sched.regions) sets.push_back(rs.config);
    milling::LiveStability live(job_, "", sets, {},
                                milling::PoseDynamics{ps.model_resolved, sched.model, ps.axis, ps.modes});
    for (std::size_t i = 0; i < r_.stops.size(); ++i) {
      PathStop& st = r_.stops[i];
      if (!ran[i])
        throw Stop{
            Stage::kVerify, Outcome::kNotVerified,
            st.name + " at " + config::describe_pose(st.joints_deg) + ": no region of the tuned schedule holds it"};
      const analysis::RegionSet& set = sched.regions[*ran[i]];
      st.region = set.name;
      st.gain_ns_per_m = set.gain_ns_per_m;
      const analysis::PredictedImprovement p =
          analysis::predicted_improvement(set.config, sched.model, ps, st.joints_deg);
      st.predicted_improvement_pct = p.pct, st.predicted_sigma_pct = p.sigma_pct;
      const auto d = std::find_if(run.dwells.begin(), run.dwells.end(),
                                  [&](const EmulatedDwell& e) { return same_pose(e.joints_deg, st.joints_deg, 0.05); });
      if (d != run.dwells.end())
        st.on_cell = true, st.records = d->records, st.measured_improvement_pct = d->measured_improvement_pct,
        st.coherence_min = d->coherence_min;
      const milling::LiveLimits l = live.compute(r_.job_rpm, *ran[i], set.gain_ns_per_m, st.joints_deg);
      st.open_limit_mm = l.open_mm;
      st.loop_open_limit_mm = l.loop_open_mm > 0.0 ? l.loop_open_mm : l.open_mm;
      st.damped_limit_mm = l.damped_valid ? l.damped_mm : 0.0;
      r_.method = l.method + " (the robot in its plane, on the mapped model)";
      if (!l.damped_valid || !l.loop_model_verified) st.limit_note = l.problem;
      say_(fmt("commission:   %s (%s): improvement %.1f %% measured, %.1f +/- %.1f %% predicted on the map (one sigma "
               "of its spread there; %d records); the job at %.0f rpm: %.3f mm damped, %.3f mm open loop",
               st.name.c_str(), st.region.c_str(), st.measured_improvement_pct, st.predicted_improvement_pct,
               st.predicted_sigma_pct, st.records, r_.job_rpm, st.damped_limit_mm, st.open_limit_mm) +
           (st.limit_note.empty() ? std::string() : " (" + st.limit_note + ")"));
    }
    judge(run);
  }

  // The verify run's verdict: somewhere the damper runs, no trip, nothing out of the map, and at every stop the
  // improvement as predicted and the cut no worse. Throws Stop with the first that fails.
  void judge(const EmulatedPathRun& run) const {
    if (std::all_of(r_.stops.begin(), r_.stops.end(), [](const PathStop& st) { return st.gain_ns_per_m == 0.0; }))
      throw Stop{
          Stage::kVerify, Outcome::kNotVerified,
          fmt("at no stop does the damper run: every set that was tuned makes the job's cut at %.0f rpm shallower than "
              "the open loop somewhere in its region, down to K = 0 (try more regions: --max-regions)",
              r_.job_rpm)};
    if (run.trip != "none")
      throw Stop{Stage::kVerify, Outcome::kNotVerified, "the controller tripped along the path: " + run.trip};
    if (run.pose_out_of_map > 0)
      throw Stop{Stage::kVerify, Outcome::kNotVerified,
                 fmt("the pose left the tuned map %llu times along the path", run.pose_out_of_map)};
    for (const auto& st : r_.stops) {
      if (!st.improvement_held(s_.improvement_tolerance_points, s_.peak_tolerance, s_.prediction_sigmas))
        throw Stop{
            Stage::kVerify, Outcome::kNotVerified,
            st.name +
                (st.on_cell
                     ? fmt(": the improvement measured on the cell, %.1f %% (%d records), is not within %.1f points "
                           "of the map's %.1f %%, nor within %.0f sigma of it (%.1f points), nor the damped peak "
                           "within %.0f %% of the predicted (%+.1f %%)",
                           st.measured_improvement_pct, st.records, s_.improvement_tolerance_points,
                           st.predicted_improvement_pct, s_.prediction_sigmas,
                           s_.prediction_sigmas * st.predicted_sigma_pct, 100.0 * s_.peak_tolerance,
                           100.0 * st.peak_error())
                     : std::string(": the emulator measured nothing there (the stop too short for a record)"))};
      if (!st.cut_not_worse())
        throw Stop{
            Stage::kVerify, Outcome::kNotVerified,
            st.name + fmt(": the damper makes the job's cut worse there: %.3f mm damped against %.3f mm open loop (the "
                          "same model) at %.0f rpm",
                          st.damped_limit_mm, st.loop_open_limit_mm, r_.job_rpm)};
    }
  }

  void write() {
    std::ostringstream h;
    h << "# robodamp commission --along-path wrote this (docs/pose_dynamics.md) for the cell " << s_.config_path
      << " and the job " << s_.job_path << ":\n#   " << s_.command_line
      << "\n# Verified on the HIL emulator along the path:";
    for (const auto& st : r_.stops)
      h << fmt(" %s %s %.1f %% measured / %.1f %% predicted, the job %.3f / %.3f mm damped / open;", st.name.c_str(),
               config::describe_pose(st.joints_deg).c_str(), st.measured_improvement_pct, st.predicted_improvement_pct,
               st.damped_limit_mm, st.open_limit_mm);
    h << "\n#\n";
    r_.configuration_path = detail::write_configuration(dir_, "tuned.yaml", h.str());
  }

  const PathCommissionSettings& s_;
  const std::function<void(const std::string&)>& say_;
  PathCommissionResult& r_;
  fs::path dir_;
  detail::StageRunner stage_;
  config::Config cell_, identified_, tuned_;
  config::MillingConfig job_;
  config::RobotModelConfig mapped_;
  std::vector<hil::PoseWaypoint> path_;
  std::string binary_;
};

}  // namespace

PathCommissionResult commission_along_path(const PathCommissionSettings& s,
                                           const std::function<void(const std::string&)>& progress) {
  PathCommissionResult r;
  const auto t0 = Clock::now();
  detail::run_to_outcome(r, [&] { PathRun(s, progress, r).all(); });
  r.wall_s = seconds_since(t0);
  std::error_code ec;
  if (fs::is_directory(s.out_dir, ec)) {
    r.report_path = (fs::path(s.out_dir) / "report.html").string();
    if (const std::string e = write_path_report(s, r, r.report_path); !e.empty()) {
      progress("commission: the report: " + e);
      r.report_path.clear();
    }
  }
  return r;
}

}  // namespace robodamp::commission
