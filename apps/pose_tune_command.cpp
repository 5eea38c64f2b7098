#include "apps/pose_tune_command.hpp"

#include <iostream>

#include "identify/pose_fit_inputs.hpp"
#include "tune/pose_tune_file.hpp"
#include "tune/pose_tune_report.hpp"

namespace robodamp::apps {

namespace {

// The measured poses (fit) and the held-out ones, by name; refused where they contradict each other under
// the model (identify::check_against_model).
void read_poses(const PoseTuneArgs& a, const config::RobotModelConfig& model, std::vector<tune::NamedPose>& measured,
                std::vector<tune::NamedPose>& held) {
  if (a.measurements.empty()) return;
  const identify::PoseFitInputs d = identify::read_pose_fit_inputs({}, a.measurements, a.hold_out, model);
  for (const auto& f : d.fit) measured.push_back({f.name, f.joints_deg});
  for (const auto& f : d.held) held.push_back({f.name, f.joints_deg});
}

}  // namespace

// The command's steps: read, tune both, score and choose (tune/pose_tune_file.hpp), report, write.
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
    tune::PoseTuneReport r = tune::pose_tune_report(a.config_path, in, held.size(), w, s, job, a.job_path);
    const tune::ControllerScore& best = w.best_score();
    if (!best.stable_everywhere) {
      std::cerr << r.text << "robodamp pose tune: no controller is stable at every pose of the map; nothing written\n";
      return 1;
    }
    if (!a.out_path.empty()) {
      const std::string header =
          "# robodamp pose tune: the " + best.name + " controller over the workspace of " + a.config_path +
          ", written by\n#   " + tune::pose_tune_command_line(a) +
          "\n# (the comparison of the robust, the scheduled and the given controllers: the same with --json)\n";
      (void)tune::write_pose_tuned_config(in.cell, w.chosen(), a.model_path, a.out_path, header);
      r.text += "wrote " + a.out_path + " (read back, every region's set analysed over its grid)\n";
      r.json["out"] = a.out_path;
    }
    if (!emit_json(a.json, r.json.dump(2), "pose tune")) return 1;
    (a.json.to_stdout() ? std::cerr : std::cout) << r.text;
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
