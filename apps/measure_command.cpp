// `robodamp measure`: the commissioning measurement (commission/measurement.hpp, docs/identification.md).
// `robodamp identify all --in DIR` turns the directory into a configuration.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "commission/measurement.hpp"
#include "commission/pose_measurements.hpp"

namespace robodamp::apps {

namespace {

struct MeasureArgs {
  std::string config_path{default_cell_config()};
  std::string out_dir;
  std::string clock;
  std::vector<double> pose_deg;
  std::string poses_file;
  bool no_hammer{false}, control_on{false}, dry_run{false};
};

int report(const commission::MeasureOutcome& r, const std::string& out_dir) {
  if (r.status == commission::MeasureStatus::kConfigError || r.status == commission::MeasureStatus::kFailed ||
      r.status == commission::MeasureStatus::kNotReady || r.status == commission::MeasureStatus::kSaturated ||
      r.status == commission::MeasureStatus::kAborted ||
      (r.status == commission::MeasureStatus::kWriteError && r.final_state.empty())) {
    std::cerr << "robodamp measure: " << r.message << '\n';
    return commission::exit_code(r.status);
  }
  if (!r.manifest.run.value("impacts", true))
    std::cout << "robodamp measure: the actuator's chirp only (no hammer), control "
              << (r.manifest.run.value("control_on", false) ? "ON" : "off") << "; the cell at rest at " << r.rest_accel_rms_mps2
              << " m/s^2 RMS before it\n";
  else if (r.manifest.backend == "simulated plant")
    std::cout << "robodamp measure: " << r.impact_records << " of " << r.impact_records_planned
              << " impact records; wrote " << r.frf_files << " FRFs to " << out_dir << '\n';
  else
    std::cout << "robodamp measure: the plant side (robodamp plant --measure-out " << out_dir
              << ") writes the impact FRFs when the run ends\n";
  std::printf("robodamp measure: state %s, trip %s, chirp played with the loop active over %.1f %% of its ticks, "
              "%llu saturated ticks, peak command %.3f V, %llu frames recorded\n",
              r.final_state.c_str(), r.trip.c_str(), 100.0 * r.chirp_active_share, r.saturated_ticks, r.peak_command_v,
              r.recorded_frames);
  if (r.status != commission::MeasureStatus::kOk) std::cerr << "robodamp measure: " << r.message << '\n';
  return commission::exit_code(r.status);
}

int measure(const MeasureArgs& a) {
  commission::MeasureOptions o{a.clock, a.pose_deg, {}};
  o.impacts = !a.no_hammer;
  o.control_on = a.control_on;
  if (a.dry_run) {
    std::cout << commission::measurement_plan(a.config_path, o);
    return 0;
  }
  if (a.poses_file.empty()) return report(commission::measure(a.config_path, a.out_dir, o), a.out_dir);
  const auto poses = commission::read_measurement_poses(a.config_path, a.poses_file);  // all checked first
  int status = 0;
  const auto done = commission::measure_poses(a.config_path, poses, a.out_dir, o, [&](const commission::PoseMeasurement& m) {
    std::cout << "robodamp measure: pose '" << m.name << "' " << config::describe_pose(m.joints_deg) << " -> " << m.dir << '\n';
    status = report(m.outcome, m.dir);
  });
  std::cout << "robodamp measure: " << done.size() << " of " << poses.size() << " poses measured; index "
            << a.out_dir << "/poses.json\n";
  return status;
}

}  // namespace

void register_measure(Registry& r) {
  auto a = std::make_shared<MeasureArgs>();
  CLI::App* sub = r.add("measure",
                        "Commissioning measurement: control off, amplifier on, a chirp on the actuator and hammer impacts "
                        "at every location, recorded for `identify all`",
                        [a] { return measure(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for the recording, the FRFs and measurement.json")->required();
  sub->add_option("--clock", a->clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  auto* pose = r.numbers(sub, "--pose", a->pose_deg, {"deg", -360.0, 360.0},
                         "The robot's joint angles, one per joint of the configuration's pose_schedule.model: the "
                         "simulated plant stands there (on hardware: where the robot stands); written to measurement.json");
  sub->add_option("--poses", a->poses_file,
                  "Measure at every pose of this file (its poses: list of {name, joints_deg}, e.g. a robot model "
                  "file), each into --out/<name>/, indexed in --out/poses.json")
      ->check(CLI::ExistingFile)
      ->excludes(pose);
  sub->add_flag("--no-hammer", a->no_hammer,
                "The actuator's chirp only, no impacts (a real cell: your modal kit's tap tests give the other FRFs)");
  sub->add_flag("--control-on", a->control_on,
                "Run the configuration's controller through the chirp (the closed loop at the actuator and the loop gain; "
                "implies nothing about impacts)");
  sub->add_flag("--dry-run", a->dry_run, "Print what would run (levels, durations, what moves) and stop");
}

}  // namespace robodamp::apps
