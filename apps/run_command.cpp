// `robodamp run`: the deployment entry point. Builds the cell (runtime/cell.hpp) from a configuration,
// takes it through its lifecycle (configure, activate, run, deactivate, cleanup) and prints the summary.
// The simulated backend paces the simulated plant in real time; can + modbus sections run the hardware
// (a CAN interface or the HIL emulator).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "apps/cli.hpp"
#include "runtime/run_summary_text.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"
#include "sim_plant/fault_text.hpp"

namespace robodamp::apps {

namespace {

struct RunArgs {
  std::string config_path{default_cell_config()};
  double duration_s{10.0};
  std::string record_path;
  JsonOut json;
  std::string histogram_path;  // wake-up latency histogram in cyclictest's --histfile format
  std::string clock;
  double impact_every_s{2.0};
  std::string job_path;
  double spindle_rpm{0.0};
  bool no_harmonic_notch{false};
  std::vector<double> pose_deg;  // pose_schedule, simulated plant: the robot stands here
  bool no_pose_schedule{false};
  std::vector<std::string> faults;  // simulated plant: KIND:START_S[:DURATION_S]
};

int exit_status(const runtime::Status& s) { return s.kind == runtime::StatusKind::kConfigError ? 2 : 1; }

// 0 ended safe (disarmed, or shut down by a signal); 2 configuration error; 4 ended in a fault trip;
// 5 never armed (the arming policy's deadline passed, or the run ended first); 1 other (devices, recording).
int run_loop(const RunArgs& a) {
  config::Config cfg = config::load_config_file(a.config_path);
  if (a.no_harmonic_notch) cfg.controller.harmonic_notch.reset();
  if (!a.job_path.empty()) cfg.spindle.job = cfg.spindle.job_resolved = a.job_path;
  runtime::CellOptions o;
  if (!a.clock.empty()) o.clock = a.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  o.impact_every_s = a.impact_every_s;
  o.record_path = a.record_path;
  o.pose_deg = a.pose_deg;
  o.pose_schedule_off = a.no_pose_schedule;
  if (a.spindle_rpm > cfg.spindle.rpm_max) {  // the loop would refuse the command: said before anything runs
    std::cerr << "robodamp run: --spindle-rpm = " << a.spindle_rpm
              << " rpm is above spindle.rpm_max = " << cfg.spindle.rpm_max << " rpm of " << a.config_path
              << " (allowed 0 <= value <= " << cfg.spindle.rpm_max << " rpm)\n";
    return 2;
  }
  if ((!a.pose_deg.empty() || a.no_pose_schedule) && !cfg.pose_schedule) {
    std::cerr << "robodamp run: --pose and --no-pose-schedule need a configuration with pose_schedule\n";
    return 2;
  }
  std::vector<sim::Fault> faults;
  for (const auto& text : a.faults) {
    sim::Fault f;
    if (std::string e; !sim::parse_fault(text, a.duration_s, f, e)) {
      std::cerr << "robodamp run: --fault = " << e << '\n';
      return 2;
    }
    faults.push_back(f);
  }
  runtime::Cell cell(cfg, o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    std::cerr << s.message << '\n';
    return exit_status(s);
  }
  if (!faults.empty() && cell.hardware()) {
    std::cerr << "robodamp run: --fault needs the simulated plant (this configuration runs the hardware)\n";
    return 2;
  }
  for (const auto& f : faults) cell.plant().faults().add(f);
  if (a.spindle_rpm > 0.0) cell.schedule(1, {rt::CommandKind::kSetSpindle, a.spindle_rpm});
  rt::install_shutdown_handlers();
  spdlog::info("robodamp run: {} at {} Hz on the {} clock for {} s against {} (Ctrl-C ends it through the safe state)",
               a.config_path, cfg.loop.rate_hz, config::to_string(cell.config().loop.clock), a.duration_s,
               cell.hardware() ? "the hardware" : "the simulated plant");
  if (runtime::Status s = cell.activate(a.duration_s); !s.ok()) {
    std::cerr << "robodamp run: " << s.message << '\n';
    return exit_status(s);
  }
  cell.wait();
  if (runtime::Status s = cell.deactivate(); !s.ok()) std::cerr << "robodamp run: " << s.message << '\n';
  const runtime::RunSummary& s = cell.summary();
  std::cout << runtime::summary_text(s);
  if (!emit_json(a.json, runtime::summary_json(s).dump(2), "run")) return 1;
  if (!a.histogram_path.empty() && !runtime::write_latency_histogram(a.histogram_path, s)) {
    std::cerr << "--histogram " << a.histogram_path << ": cannot write\n";
    return 1;
  }
  if (s.record_errors > 0) return 1;
  if (s.trip == "signal") return 0;
  if (s.trip != "none") return 4;
  if (s.never_armed()) {
    std::cerr << "robodamp run: the loop never armed: " << s.arming.attempts
              << " attempt(s) within supervision.arm_deadline_s = " << s.arming.deadline_s
              << " s, last refusal: " << rt::to_string(s.arming.last_refusal) << '\n';
    return 5;
  }
  return 0;
}

}  // namespace

void register_run(Registry& r) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* sub = r.add("run",
                        "The real-time loop against the simulated plant, or the hardware (can + modbus sections: "
                        "a CAN interface or the HIL emulator); Ctrl-C ends it safely",
                        [a] { return run_loop(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  r.number(sub, "--duration", a->duration_s, {"s", 0.0, 604800.0, true, false, "one week"}, "Run time in seconds");
  sub->add_option("--record", a->record_path, "Record every tick to this file (binary, docs/recording_format.md)");
  r.json(sub, a->json, "The run summary");
  sub->add_option("--histogram", a->histogram_path,
                  "Write the wake-up latency histogram (cyclictest --histfile layout) to this file");
  sub->add_option("--clock", a->clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  r.number(sub, "--impact-every", a->impact_every_s, {"s", 0.0, 86400.0, false, false, "0 = none"},
           "Simulated plant: a hammer hit at the TCP every S seconds (bench.impact_peak_n)");
  sub->add_option(
         "--job", a->job_path,
         "Milling job (config/milling/*.yaml) for live stability and the chatter indicator; overrides spindle.job")
      ->check(CLI::ExistingFile);
  sub->add_flag("--no-harmonic-notch", a->no_harmonic_notch,
                "Run without the configuration's controller.harmonic_notch (to compare the bank on and off)");
  r.number(sub, "--spindle-rpm", a->spindle_rpm, {"rpm", 0.0, 200000.0, false, false, "0 = stopped"},
           "The spindle speed from the start (as the robot's register or a DDS request would set it)");
  r.numbers(sub, "--pose", a->pose_deg, {"deg", -360.0, 360.0},
            "pose_schedule, simulated plant: the robot stands at these joint angles (one per joint)");
  sub->add_option(
      "--fault", a->faults,
      "Simulated plant, a fault drill: KIND:START_S[:DURATION_S] (sensor_nan, amplifier_fault, ... from loop "
      "time START_S; repeatable); actuator_saturated:START_S:DURATION_S:FORCE_N limits the actuator to FORCE_N "
      "(default 0)");
  sub->add_flag("--no-pose-schedule", a->no_pose_schedule,
                "pose_schedule: run the first region's set at every pose and ignore the joint angles (scheduling off)");
}

}  // namespace robodamp::apps
