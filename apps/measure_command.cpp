// `robodamp measure`: the commissioning measurement (commission/measurement.hpp, docs/identification.md).
// `robodamp identify all --in DIR` turns the directory into a configuration.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "commission/measurement.hpp"
#include "commission/path_measurement.hpp"
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
  bool along_path{false};
  int dwells{1};
  double duration_s{3600.0}, still_deg{0.05};
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
              << (r.manifest.run.value("control_on", false) ? "ON" : "off") << "; the cell at rest at "
              << r.rest_accel_rms_mps2 << " m/s^2 RMS before it\n";
  else if (r.manifest.backend == "simulated plant")
    std::cout << "robodamp measure: " << r.impact_records << " of " << r.impact_records_planned
              << " impact records; wrote " << r.frf_files << " FRFs to " << out_dir << '\n';
  else
    std::cout << "robodamp measure: the plant side (robodamp plant --measure-out " << out_dir
              << ") writes the impact FRFs when the run ends\n";
  std::printf(
      "robodamp measure: state %s, trip %s, chirp played with the loop active over %.1f %% of its ticks, "
      "%llu saturated ticks, peak command %.3f V, %llu frames recorded\n",
      r.final_state.c_str(), r.trip.c_str(), 100.0 * r.chirp_active_share, r.saturated_ticks, r.peak_command_v,
      r.recorded_frames);
  if (r.status != commission::MeasureStatus::kOk) std::cerr << "robodamp measure: " << r.message << '\n';
  return commission::exit_code(r.status);
}

int measure_along_path(const MeasureArgs& a, const commission::MeasureOptions& o) {
  commission::PathMeasureOptions p{o, a.dwells, a.duration_s, a.still_deg};
  const config::Config cfg = config::load_config_file(a.config_path);
  const commission::PathMeasureOutcome r = commission::measure_along_path(cfg, a.config_path, a.out_dir, p);
  for (const auto& d : r.dwells) {
    if (d.measured)
      std::printf("robodamp measure: %s at %s (still from %.2f s): the chirp %.2f-%.2f s -> %s\n", d.name.c_str(),
                  config::describe_pose(d.joints_deg).c_str(), d.still_s, d.chirp_start_s, d.chirp_end_s,
                  d.dir.c_str());
    else
      std::printf("robodamp measure: %s (still from %.2f s) not measured: %s\n", d.name.c_str(), d.still_s,
                  d.skipped.c_str());
  }
  if (r.pauses > 0)
    std::printf("robodamp measure: %d pauses shorter than commissioning.settle_s, not stops (see the log)\n", r.pauses);
  std::printf(
      "robodamp measure: %d of %d dwells measured along the path; state %s, trip %s, %llu saturated ticks, peak "
      "command %.3f V; index %s/poses.json\n",
      r.measured(), a.dwells, r.run.final_state.c_str(), r.run.trip.c_str(), r.run.saturated_ticks,
      r.run.peak_command_v, a.out_dir.c_str());
  if (r.run.status != commission::MeasureStatus::kOk) std::cerr << "robodamp measure: " << r.run.message << '\n';
  return commission::exit_code(r.run.status);
}

int measure(const MeasureArgs& a) {
  commission::MeasureOptions o{a.clock, a.pose_deg, {}};
  o.impacts = !a.no_hammer;
  o.control_on = a.control_on;
  if (a.dry_run) {
    std::cout << commission::measurement_plan(a.config_path, o);
    return 0;
  }
  if (a.along_path) return measure_along_path(a, o);
  if (a.poses_file.empty()) return report(commission::measure(a.config_path, a.out_dir, o), a.out_dir);
  const auto poses = commission::read_measurement_poses(a.config_path, a.poses_file);  // all checked first
  int status = 0;
  const auto done =
      commission::measure_poses(a.config_path, poses, a.out_dir, o, [&](const commission::PoseMeasurement& m) {
        std::cout << "robodamp measure: pose '" << m.name << "' " << config::describe_pose(m.joints_deg) << " -> "
                  << m.dir << '\n';
        status = report(m.outcome, m.dir);
      });
  std::cout << "robodamp measure: " << done.size() << " of " << poses.size() << " poses measured; index " << a.out_dir
            << "/poses.json\n";
  return status;
}

}  // namespace

void register_measure(Registry& r) {
  auto a = std::make_shared<MeasureArgs>();
  CLI::App* sub =
      r.add("measure",
            "Commissioning measurement: control off, amplifier on, a chirp on the actuator and hammer impacts "
            "at every location, recorded for `identify all`",
            [a] { return measure(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for the recording, the FRFs and measurement.json")->required();
  sub->add_option("--clock", a->clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  auto* pose =
      r.numbers(sub, "--pose", a->pose_deg, {"deg", -360.0, 360.0},
                "The robot's joint angles, one per joint of the configuration's pose_schedule.model: the "
                "simulated plant stands there (on hardware: where the robot stands); written to measurement.json");
  sub->add_option("--poses", a->poses_file,
                  "Measure at every pose of this file (its poses: list of {name, joints_deg}, e.g. a robot model "
                  "file), each into --out/<name>/, indexed in --out/poses.json")
      ->check(CLI::ExistingFile)
      ->excludes(pose);
  auto* path =
      sub->add_flag("--along-path", a->along_path,
                    "Measure at each stop of the moving robot (its joints read from the robot: modbus.robot."
                    "joints_register or dds.joint_states): the chirp once it has stood still for commissioning."
                    "settle_s, the plant side's hammer after it; each stop into --out/dwell_<k>/, indexed in "
                    "--out/poses.json")
          ->excludes(pose);
  sub->get_option("--poses")->excludes(path);
  r.whole_number(sub, "--dwells", a->dwells, {"dwells", 1, 1000},
                 "--along-path: the run ends once this many stops are measured");
  r.number(sub, "--duration", a->duration_s, {"s", 1.0, 86400.0}, "--along-path: the run ends after this long at most");
  r.number(sub, "--still-deg", a->still_deg, {"deg", 0.0, 10.0, true},
           "--along-path: a joint further than this from where it stopped: the robot moves");
  sub->add_flag("--no-hammer", a->no_hammer,
                "The actuator's chirp only, no impacts (a real cell: your modal kit's tap tests give the other FRFs)");
  sub->add_flag(
      "--control-on", a->control_on,
      "Run the configuration's controller through the chirp (the closed loop at the actuator and the loop gain; "
      "implies nothing about impacts)");
  sub->add_flag("--dry-run", a->dry_run, "Print what would run (levels, durations, what moves) and stop");
}

}  // namespace robodamp::apps
