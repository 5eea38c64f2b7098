// `robodamp run`: the deployment entry point. Builds the cell (runtime/cell.hpp) from a configuration,
// takes it through its lifecycle (configure, activate, run, deactivate, cleanup) and prints the summary.
// The simulated backend paces the simulated plant in real time; can + modbus sections run the hardware
// (a CAN interface or the HIL emulator).
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "runtime/run_summary_text.hpp"
#include "runtime/run_to_end.hpp"

namespace robodamp::apps {

namespace {

struct RunArgs {
  RunArgs() { request.config_path = default_cell_config(); }
  runtime::RunRequest request;
  JsonOut json;
  std::string histogram_path;  // wake-up latency histogram in cyclictest's --histfile format
};

// The exit statuses: runtime/run_to_end.hpp, and 1 when the JSON or the histogram cannot be written.
int run_loop(const RunArgs& a) {
  const runtime::RunOutcome r = runtime::run_to_end(a.request, std::cerr);
  if (!r.summary) return r.status;
  const runtime::RunSummary& s = *r.summary;
  std::cout << runtime::summary_text(s);
  if (!emit_json(a.json, runtime::summary_json(s).dump(2), "run")) return 1;
  if (!a.histogram_path.empty() && !runtime::write_latency_histogram(a.histogram_path, s)) {
    std::cerr << "--histogram " << a.histogram_path << ": cannot write\n";
    return 1;
  }
  return runtime::run_exit_status(s, std::cerr);
}

}  // namespace

void register_run(Registry& r) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* sub = r.add("run",
                        "The real-time loop against the simulated plant, or the hardware (can + modbus sections: "
                        "a CAN interface or the HIL emulator); Ctrl-C ends it safely",
                        [a] { return run_loop(*a); });
  sub->add_option("--config", a->request.config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  r.number(sub, "--duration", a->request.duration_s, {"s", 0.0, 604800.0, true, false, "one week"},
           "Run time in seconds");
  sub->add_option("--record", a->request.record_path,
                  "Record every tick to this file (binary, docs/recording_format.md)");
  r.json(sub, a->json, "The run summary");
  sub->add_option("--histogram", a->histogram_path,
                  "Write the wake-up latency histogram (cyclictest --histfile layout) to this file");
  sub->add_option("--clock", a->request.clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  r.number(sub, "--impact-every", a->request.impact_every_s, {"s", 0.0, 86400.0, false, false, "0 = none"},
           "Simulated plant: a hammer hit at the TCP every S seconds (bench.impact_peak_n)");
  sub->add_option(
         "--job", a->request.job_path,
         "Milling job (config/milling/*.yaml) for live stability and the chatter indicator; overrides spindle.job")
      ->check(CLI::ExistingFile);
  sub->add_flag("--no-harmonic-notch", a->request.no_harmonic_notch,
                "Run without the configuration's controller.harmonic_notch (to compare the bank on and off)");
  r.number(sub, "--spindle-rpm", a->request.spindle_rpm, {"rpm", 0.0, 200000.0, false, false, "0 = stopped"},
           "The spindle speed from the start (as the robot's register or a DDS request would set it)");
  r.numbers(sub, "--pose", a->request.pose_deg, {"deg", -360.0, 360.0},
            "pose_schedule, simulated plant: the robot stands at these joint angles (one per joint)");
  sub->add_option(
      "--fault", a->request.faults,
      "Simulated plant, a fault drill: KIND:START_S[:DURATION_S] (sensor_nan, amplifier_fault, ... from loop "
      "time START_S; repeatable); actuator_saturated:START_S:DURATION_S:FORCE_N limits the actuator to FORCE_N "
      "(default 0)");
  sub->add_flag("--no-pose-schedule", a->request.no_pose_schedule,
                "pose_schedule: run the first region's set at every pose and ignore the joint angles (scheduling off)");
}

}  // namespace robodamp::apps
