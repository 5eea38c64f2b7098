// `robodamp pose`: the planar-robot study's pose-dependent robot dynamics (robot/, docs/pose_dynamics.md).
//   pose frf  --model F (--joints Q1 Q2 Q3 | --pose NAME) [--json] [--plot PNG]: the TCP's modes and FRF at a pose
//   pose table --model F: the model's first mode at each named pose beside the published values
//   pose fit  --model F --measured Q1,Q2,Q3:FRF.csv ... [--direction yy] [--out fitted.yaml]: the joints'
//             stiffness and damping from measured TCP FRFs at poses (particle swarm, then BOBYQA)
//   pose modes --model F (--measurements DIR [--hold-out NAME ...] --out F2 | --joints Q | --pose NAME): the
//             modes measured at poses as the model's measured_modes, or the mapped modes at a pose
//   pose map  --model F --vary J1 J2 [--steps N] [--job JOB] [--json F] [--plot PNG]: first-mode frequency,
//             modal stiffness and (with a job) the minimum limiting depth over a grid of two joints
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "apps/pose_command.hpp"
#include "apps/pose_modes_command.hpp"
#include "apps/pose_tune_command.hpp"
#include "milling/pose_map.hpp"
#include "robot/pose_report.hpp"
#include "robot/robot_model.hpp"

namespace robodamp::apps {

namespace {

using nlohmann::json;

std::vector<double> pose_of(const config::RobotModelConfig& m, const PoseArgs& a) {
  if (!a.pose_name.empty()) {
    for (const auto& p : m.poses)
      if (p.name == a.pose_name) return p.joints_deg;
    std::string known;
    for (const auto& p : m.poses) known += (known.empty() ? "" : ", ") + p.name;
    throw config::ConfigError(
        {config::Problem{m.source, {}, "poses", "--pose-name = '" + a.pose_name + "' is not one of: " + known}});
  }
  if (!a.joints_deg.empty()) return a.joints_deg;
  if (m.poses.empty())
    throw config::ConfigError({config::Problem{m.source, {}, "poses", "give --joints (the file names no pose)"}});
  return m.poses.front().joints_deg;
}

int run_frf(const config::RobotModelConfig& m, const PoseArgs& a) {
  const std::vector<double> q = pose_of(m, a);
  robot::PoseReport r = robot::pose_frf_report(m, q, static_cast<std::size_t>(a.modes), a.band_hz[0], a.band_hz[1]);
  if (!a.csv_path.empty() &&
      !robot::write_frf_csv(robot::at_pose(m, q), a.band_hz[0], a.band_hz[1], a.csv_step_hz, a.direction, a.csv_path)) {
    std::cerr << "--csv-out " << a.csv_path << ": cannot write\n";
    return 1;
  }
  if (!also_json_out(a, r.json)) return 1;
  return print_report(
      r.json.dump(2), a.json, "pose", r.text, a.plot_path,
      [&] { return robot::plot_pose_frf(r.plot_data, a.plot_path); }, a.plot_path);
}

int run_table(const config::RobotModelConfig& m, const PoseArgs& a) {
  const robot::PoseReport r = robot::pose_table_report(m);
  if (!also_json_out(a, r.json)) return 1;
  return print_report(r.json.dump(2), a.json, "pose", r.text, "", {}, "");
}

int run_map(const config::RobotModelConfig& m, const PoseArgs& a) {
  const std::size_t n = m.joints.size();
  if (a.vary.size() != 2 || a.vary[0] == a.vary[1] || a.vary[0] < 1 || a.vary[1] < 1 ||
      static_cast<std::size_t>(a.vary[0]) > n || static_cast<std::size_t>(a.vary[1]) > n) {
    std::cerr << "robodamp pose map: --vary takes two different joints, 1.." << n << '\n';
    return 2;
  }
  std::optional<config::MillingConfig> job;
  if (!a.job_path.empty()) job = config::load_milling_config(a.job_path);
  milling::PoseMapRequest req;
  req.base_deg = pose_of(m, a);
  req.joint_a = static_cast<std::size_t>(a.vary[0] - 1), req.joint_b = static_cast<std::size_t>(a.vary[1] - 1);
  req.steps = a.steps;
  req.job = job ? &*job : nullptr;
  req.zero_order = a.method == "zoa";
  const milling::PoseMap map = milling::pose_map(m, req, [&](int row, int rows) {
    std::cerr << "robodamp pose map: row " << row << " of " << rows << " done ("
              << (req.zero_order ? "zero-order preview" : "SDM") << ")\n";
  });
  const milling::PoseMapReport r = milling::pose_map_report(m, req, map, a.job_path);
  if (!also_json_out(a, r.json)) return 1;
  return print_report(
      r.json.dump(2), a.json, "pose", r.text, a.plot_path,
      [&] { return milling::plot_pose_map(r, req, map, a.plot_path); }, a.plot_path);
}

int run_pose(const PoseArgs& given) {
  PoseArgs a = given;
  if (a.what == "tune") {
    a.tune.measurements = a.measurements, a.tune.hold_out = a.hold_out, a.tune.job_path = a.job_path;
    a.tune.out_path = a.out_path, a.tune.json = a.json, a.tune.seed = a.seed;
    if (a.model_given) a.tune.model_path = a.model_path;
    return run_pose_tune(a.tune);
  }
  a.plot_path = plot_file(a.plot_dir, a.plot_path, "pose_" + a.what + ".png");
  for (const auto& [flag, band] : {std::pair{"--band-hz", &a.band_hz}, std::pair{"--fit-band-hz", &a.fit_band_hz}})
    if (band->size() != 2 || !((*band)[0] < (*band)[1])) {
      std::cerr << "robodamp pose: " << flag << ": two frequencies LO HI in Hz, LO < HI\n";
      return 2;
    }
  try {
    const config::RobotModelConfig m = config::load_robot_model(a.model_path);
    if (a.what == "frf") return run_frf(m, a);
    if (a.what == "table") return run_table(m, a);
    if (a.what == "fit") return run_fit(m, a);
    if (a.what == "modes")
      return run_pose_modes(m, {a.measurements, a.hold_out, a.joints_deg, a.pose_name, a.modes_given ? a.modes : 3,
                                a.out_path, a.json, a.plot_path, a.vary.empty() ? 2 : a.vary[0]});
    return run_map(m, a);
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp pose: " << e.what() << '\n';
    return 2;
  }
}

}  // namespace

namespace {
void add_fit_options(Registry& r, CLI::App* sub, PoseArgs& a);
}  // namespace

void register_pose(Registry& r) {
  auto a = std::make_shared<PoseArgs>();
  CLI::App* sub =
      r.add("pose",
            "Pose-dependent robot dynamics (the planar-robot study): `pose frf` (modes and TCP FRF at a pose), `pose "
            "fit` (joints from measured FRFs), `pose modes` "
            "(the modes measured at poses into the model, or the mapped modes at a pose), `pose table` (the first mode "
            "at the model's named poses), `pose map` (first mode over two joints), `pose tune` (a robust set and a "
            "schedule drawn from the data over a configuration's workspace, the better written)",
            [a] { return run_pose(*a); });
  sub->add_option("what", a->what, "frf, table, fit, modes, map or tune")
      ->required()
      ->check(CLI::IsMember({"frf", "table", "fit", "modes", "map", "tune"}));
  sub->add_option("--model", a->model_path,
                  "Robot model file (config/robots/*.yaml); tune: the pose-indexed model (default the configuration's "
                  "pose_schedule.model)")
      ->check(CLI::ExistingFile)
      ->each([a](const std::string&) { a->model_given = true; });
  sub->add_option("--config", a->tune.config_path,
                  "tune: the configuration with a pose_schedule (model, axis, workspace)")
      ->check(CLI::ExistingFile);
  r.whole_number(sub, "--evaluations", a->tune.evaluations, {"(evaluations per polarity)", 10, 5000},
                 "tune: each set's global search");
  r.whole_number(sub, "--polish", a->tune.polish, {"(evaluations)", 0, 5000}, "tune: each set's local polish");
  r.whole_number(sub, "--max-regions", a->tune.max_regions, {"(regions)", 1, 16},
                 "tune: the scheduled controller's regions at most");
  r.whole_number(sub, "--map-points", a->tune.map_points, {"(points per joint)", 2, 41},
                 "tune: the workspace map's grid along the joints that move the dominant mode (default 9)");
  r.number(sub, "--overlap-deg", a->tune.overlap_deg, {"deg", 0.0, 30.0},
           "tune: neighbouring regions overlap by this (the hand-over's hysteresis)");
  r.number(sub, "--worse-mode-pct", a->tune.worse_mode_pct, {"%", 0.0, 20.0},
           "tune: a set serves while no mode in the damping band is more than this much worse than open loop (default "
           "0: never worse)");
  r.numbers(sub, "--joints", a->joints_deg, {"deg", -360.0, 360.0},
            "frf, map, modes: the pose, one relative angle per joint");
  // --pose is the joint angles in run, cut, lobes, sle and measure: here it named a pose (docs/cli.md).
  r.renamed(sub->add_option("--pose-name", a->pose_name, "frf, map, modes: a pose the model file names"), "NAME",
            sub->add_option("--pose", a->pose_name, "frf, map, modes: a pose the model file names"),
            "--pose is joint angles in every other command");
  r.whole_number(sub, "--modes", a->modes, {"(modes)", 1, 20},
                 "frf: how many modes (default 4); modes: how many of the model's (default 3)")
      ->each([a](const std::string&) { a->modes_given = true; });
  r.numbers(sub, "--band-hz", a->band_hz, {"Hz", 0.0, 1e4, true, false}, "frf: FRF band LO HI");
  r.json(sub, a->json, "The result (modes, the table, the fit or the map)");
  r.deprecated(sub->add_option("--json-out", a->json_out_path, "Also write the JSON to this file"), "--json FILE");
  r.plot_dir(sub, a->plot_dir,
             "frf, map, modes: pose_frf.png, pose_map.png or pose_modes.png (the modes along --vary's first joint)");
  r.deprecated(sub->add_option("--plot", a->plot_path, "frf, map: write the plot to this file (PNG)"),
               "--plot-dir DIR");
  sub->add_option("--vary", a->vary,
                  "map: the two joints to vary over their travel (1-based); modes: the first, the plot's joint");
  sub->add_option("--job", a->job_path,
                  "map: a milling job whose structure has a robot pose part (its minimum depth per pose); tune: the "
                  "job scored over the workspace map")
      ->check(CLI::ExistingFile);
  sub->add_option("--method", a->method,
                  "map: sdm (default): the job's minimum by semi-discretization over its SDM speeds; zoa: the "
                  "zero-order method, a fast preview")
      ->check(CLI::IsMember({"sdm", "zoa"}));
  r.whole_number(sub, "--steps", a->steps, {"(steps per joint)", 2, 201}, "map: grid steps per joint");
  add_fit_options(r, sub, *a);
}

namespace {

// pose fit's options (and --out, --csv-out, which fit, modes, tune and frf share).
void add_fit_options(Registry& r, CLI::App* sub, PoseArgs& a) {
  sub->add_option("--measured", a.measured, "fit: a measured TCP receptance at a pose, Q1,Q2,...:FRF.csv (repeatable)");
  sub->add_option(
         "--measurements", a.measurements,
         "fit, modes: robodamp measure --pose directories (or a --poses directory: all its poses), their joint angles "
         "and driving-point FRFs; the direction is their configuration's pose_schedule.axis")
      ->check(CLI::ExistingDirectory);
  sub->add_option(
      "--hold-out", a.hold_out,
      "fit, modes: pose names (of --measurements) kept out of the fit or the map: the error is reported there");
  sub->add_option("--direction", a.direction, "fit: which TCP receptance the FRFs are; frf: which one --csv-out writes")
      ->check(CLI::IsMember({"xx", "yy", "xy"}));
  r.numbers(sub, "--fit-band-hz", a.fit_band_hz, {"Hz", 0.0, 1e4, true, false},
            "fit: band LO HI (the planar-robot study: 10 30)");
  r.whole_number(
      sub, "--fit-modes", a.fit_modes, {"(modes)", 0, 20},
      "fit: compare the model as its N lowest modes with viscous damping, the plant a schedule predicts with "
      "(default: the measurements' pose_schedule.modes; 0, and for --measured: the model's own receptance)");
  r.whole_number(sub, "--restarts", a.restarts, {"(restarts)", 1, 100}, "fit: swarms with seeds seed, seed+1, ...");
  r.whole_number(sub, "--particles", a.particles, {"(particles)", 4, 1000}, "fit: particles per swarm");
  r.whole_number(sub, "--iterations", a.iterations, {"(iterations)", 1, 10000}, "fit: iterations per swarm");
  r.whole_number(sub, "--seed", a.seed, {"(seed)", 0, 2147483647}, "fit: the first swarm's seed");
  sub->add_option("--out", a.out_path,
                  "fit: write the fitted robot model file here; modes: the model with its measured modes; tune: the "
                  "configuration with the chosen controller");
  // --csv is a table read in identify and chatter: here it was one written.
  r.renamed(sub->add_option("--csv-out", a.csv_path,
                            "frf: write the --direction receptance as freq_hz,re_m_per_n,im_m_per_n over --band-hz"),
            "FILE", sub->add_option("--csv", a.csv_path, "frf: write the receptance to this table"),
            "--csv is a table read in every other command");
  r.number(sub, "--csv-step-hz", a.csv_step_hz, {"Hz", 0.0, 1e3, true, false}, "frf: the --csv-out frequency step");
}

}  // namespace

}  // namespace robodamp::apps
