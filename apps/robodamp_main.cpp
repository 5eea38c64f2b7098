// robodamp: active vibration damping for robotic milling. Subcommands are thin: they parse, call the
// libraries and print.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>
#include <yaml-cpp/yaml.h>

#include "analysis/loop_model.hpp"
#include "apps/analyze_command.hpp"
#include "apps/bench_command.hpp"
#include "apps/filters_command.hpp"
#include "apps/gnuplot.hpp"
#include "apps/milling_command.hpp"
#include "apps/dds_commands.hpp"
#include "apps/plant_command.hpp"
#include "apps/run_command.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/structure.hpp"
#include "control/chain_design.hpp"
#include "sim_plant/plant_model.hpp"

namespace {

using robodamp::config::ConfigError;

// Parses and designs; prints every problem and returns false if there are any.
bool load_design(const std::string& path, robodamp::control::ChainDesign& out) {
  try {
    out = robodamp::control::design_chain(robodamp::config::load_config_file(path));
    return true;
  } catch (const ConfigError& e) {
    std::cerr << e.what() << '\n';
    return false;
  }
}

int run_filters(const std::string& path, double freq_hz, bool json, const std::string& plot) {
  robodamp::control::ChainDesign d;
  if (!load_design(path, d)) return 2;
  if (!(freq_hz > 0.0 && freq_hz < 0.5 * d.params.fs_hz)) {
    std::cerr << "--freq " << freq_hz << " Hz: allowed 0 < value < " << 0.5 * d.params.fs_hz
              << " Hz (below Nyquist of loop.rate_hz)\n";
    return 2;
  }
  const auto report = robodamp::apps::filters_report(d, freq_hz);
  return robodamp::apps::print_report(report.dump(2), json, robodamp::apps::filters_table(report), plot,
                                      [&] { return robodamp::apps::plot_filters(d, plot); }, plot);
}

// A milling job (config/milling/) has a top-level `tool`; its controller parts are loaded and checked too.
bool is_milling_job(const std::string& path) {
  try {
    return YAML::LoadFile(path)["tool"].IsDefined();
  } catch (const YAML::Exception&) {
    return false;  // the configuration parser reports the syntax error
  }
}

int run_check_milling(const std::string& path) {
  try {
    const auto job = robodamp::config::load_milling_config(path);
    for (const auto& s : job.structures) (void)robodamp::milling::Structure(s, false);
    std::cout << path << ": OK (milling job, " << job.structures.size() << " structure(s), " << job.conditions.size()
              << " condition(s))\n";
    return 0;
  } catch (const ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

int run_check_config(const std::string& path) {
  if (is_milling_job(path)) return run_check_milling(path);
  robodamp::control::ChainDesign d;
  try {
    const auto cfg = robodamp::config::load_config_file(path);
    d = robodamp::control::design_chain(cfg);
    if (!cfg.robot.frfs.empty()) (void)robodamp::sim::build_plant_model(cfg);  // the plant's physical consistency
  } catch (const ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
  std::cout << path << ": OK (" << d.blocks.size() << " blocks, " << d.params.sections.count
            << " second-order sections at " << d.params.fs_hz << " Hz)\n";
  return 0;
}

int run_analyze(const std::string& path, bool json, const std::string& plot_dir) {
  try {
    const robodamp::analysis::LoopModel model(robodamp::config::load_config_file(path));
    const auto result = robodamp::analysis::analyse(model);
    const auto report = robodamp::apps::analysis_report(model, result);
    if (robodamp::apps::print_report(report.dump(2), json, robodamp::apps::analysis_table(report), plot_dir,
                                     [&] { return robodamp::apps::plot_analysis(model, result, plot_dir); },
                                     "frf_open_closed.png, nyquist.png, gain_sweep.png in " + plot_dir) != 0)
      return 1;
    return result.stable ? 0 : 3;
  } catch (const ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

int run_bench(const std::string& path, const std::string& json_path, const std::string& plot_dir) {
  try {
    const robodamp::analysis::Bench bench(robodamp::config::load_config_file(path));
    const auto report = bench.run([](const std::string& line) { std::cerr << "[bench] " << line << std::endl; });
    std::cout << robodamp::apps::bench_table(bench, report);
    if (!json_path.empty()) {
      std::ofstream out(json_path);
      out << robodamp::apps::bench_report_json(bench, report).dump(2) << '\n';
      if (!out) {
        std::cerr << "--json " << json_path << ": cannot write\n";
        return 1;
      }
      std::cout << "wrote " << json_path << '\n';
    }
    if (!plot_dir.empty()) {
      std::string err = robodamp::apps::plot_analysis(bench.model(), report.analysis, plot_dir);
      if (err.empty()) err = robodamp::apps::plot_bench(bench, report, plot_dir);
      if (!err.empty()) {
        std::cerr << "plot: " << err << '\n';
        return 1;
      }
      std::cout << "wrote plots in " << plot_dir << '\n';
    }
    if (!report.ran_closed_loop) return 3;
    return report.improvement_within_5pct && report.sweep_agrees ? 0 : 1;
  } catch (const ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"robodamp: real-time active vibration damping for robotic milling"};
  app.require_subcommand(1);

  std::string config_path = ROBODAMP_DEFAULT_CONFIG;
  double freq_hz = 9.2;
  bool json = false;
  std::string plot;
  auto* filters = app.add_subcommand("filters", "Magnitude and phase of each block and the chain, analog and digital");
  filters->add_option("--config", config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  filters->add_option("--freq", freq_hz, "Frequency in Hz")->capture_default_str();
  filters->add_flag("--json", json, "Print JSON instead of a table");
  filters->add_option("--plot", plot, "Write a Bode diagram of the blocks and the chain (PNG)");

  std::string check_path;
  auto* check = app.add_subcommand("check-config", "Validate a configuration (controller or milling job) and report every problem at once");
  check->add_option("file", check_path, "Configuration file (YAML)")->required();

  std::string plot_dir;
  auto* analyze = app.add_subcommand("analyze", "Closed-loop stability, margins, polarity and predicted improvement");
  analyze->add_option("--config", config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  analyze->add_flag("--json", json, "Print JSON instead of a table");
  analyze->add_option("--plot-dir", plot_dir, "Write FRF, Nyquist and gain-sweep plots (PNG) here");

  std::string json_path;
  auto* bench = app.add_subcommand("bench", "Simulated-plant bench run: impact tests control off/on, saturation, gain sweep");
  bench->add_option("--config", config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  bench->add_option("--json", json_path, "Write the report as JSON to this file");
  bench->add_option("--plot-dir", plot_dir, "Write plots (PNG) here");

  robodamp::apps::RunOptions run_opts;
  std::string clock;
  auto* run = app.add_subcommand("run", "The real-time loop against the simulated plant, or the hardware (can + modbus sections: "
                                        "a CAN interface or the HIL emulator); Ctrl-C ends it safely");
  run->add_option("--config", config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  run->add_option("--duration", run_opts.duration_s, "Run time in seconds")->capture_default_str();
  run->add_option("--record", run_opts.record_path, "Record every tick to this file (binary, docs/recording_format.md)");
  run->add_option("--json", run_opts.json_path, "Write the run summary as JSON to this file");
  run->add_option("--histogram", run_opts.histogram_path,
                  "Write the wake-up latency histogram (cyclictest --histfile layout) to this file");
  run->add_option("--clock", clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
  run->add_option("--impact-every", run_opts.impact_every_s,
                  "Simulated plant: a hammer hit at the TCP every S seconds (bench.impact_peak_n); 0 = none")
      ->capture_default_str();

  robodamp::apps::PlantOptions plant_opts;
  std::string pacing;
  auto* plant = app.add_subcommand("plant", "HIL plant emulator: the simulated plant behind CAN frames and Modbus registers, "
                                            "in its own process, for `robodamp run` to control");
  plant->add_option("--config", config_path, "Configuration file (YAML) with can, modbus and hil sections")->check(CLI::ExistingFile);
  plant->add_option("--pacing", pacing, "Override hil.pacing: realtime (true HIL) or lockstep (one step per command frame)")
      ->check(CLI::IsMember({"realtime", "lockstep"}));
  plant->add_option("--duration", plant_opts.duration_s, "Stop after this much plant time, s (0 = when the controller leaves)");
  plant->add_option("--json", plant_opts.json_path, "Write the report (frames, timing, measured FRFs) as JSON to this file");
  plant->add_flag("!--no-impacts", plant_opts.impacts, "Do not run the impact schedule");
  plant->add_option("--impact-location", plant_opts.impact_location, "Location id the hammer hits (default: the first FRF's excitation)");
  plant->add_option("--mounting", plant_opts.mounting_schedule,
                    "Robot mounting register changes, TIME_S:horizontal|vertical (plant time), repeatable");

  robodamp::apps::DdsClientOptions dds_opts;
  std::string dds_transport = "default";
  std::string dds_config;
  auto add_dds_options = [&](CLI::App* c) {
    c->add_option("--domain", dds_opts.domain_id, "DDS domain (default: dds.domain_id of --config, else 0)")->check(CLI::Range(0, 232));
    c->add_option("--config", dds_config, "Take the domain and transport from this configuration's dds section")->check(CLI::ExistingFile);
    c->add_option("--transport", dds_transport, "default, udp_loopback or shared_memory")
        ->check(CLI::IsMember({"default", "udp_loopback", "shared_memory"}));
  };
  auto* monitor = app.add_subcommand("monitor", "Live text view of a running loop from its DDS topics (state, vibration, command, saturation, timing)");
  add_dds_options(monitor);
  monitor->add_option("--duration", dds_opts.duration_s, "Stop after S seconds (0 = at Ctrl-C)");
  robodamp::apps::RequestOptions req_opts;
  auto* request = app.add_subcommand("request", "One supervised parameter request over DDS (needs dds.parameter_writes: true)");
  add_dds_options(request);
  request->add_option("--gain", req_opts.gain_ns_per_m, "Set the gain K, N s/m");
  request->add_option("--select", req_opts.parameter_set, "Select a parameter set (0 = the configuration's own)");
  request->add_option("--enable", req_opts.enable, "1 = arm, 0 = disarm")->check(CLI::Range(0, 1));
  request->add_option("--timeout", dds_opts.duration_s, "Wait this long for the loop and the reply, s (default 10)");

  std::string recording, csv_out;
  auto* replay = app.add_subcommand("replay", "Feed a recording's inputs through the same controller; check the commands bit for bit");
  replay->add_option("file", recording, "Recording (from run --record)")->required()->check(CLI::ExistingFile);
  auto* csv = app.add_subcommand("csv", "Export a recording as CSV");
  csv->add_option("file", recording, "Recording (from run --record)")->required()->check(CLI::ExistingFile);
  csv->add_option("-o,--out", csv_out, "Output file (default: stdout)");

  robodamp::apps::MillingOptions mill;
  mill.config_path = ROBODAMP_DEFAULT_MILLING_CONFIG;
  auto* lobes = app.add_subcommand("lobes", "Stability lobes (zero-order method) with a direct check, open loop and --damped");
  auto* sle = app.add_subcommand("sle", "Surface location error over speed and at the test conditions, with compensation");
  for (auto* sc : {lobes, sle}) {
    sc->add_option("--config", mill.config_path, "Milling job (YAML, config/milling/)")->check(CLI::ExistingFile);
    sc->add_option("--structure", mill.structure, "Which of the job's structures (default: its `structure`)");
    sc->add_flag("--json", mill.json, "Print JSON instead of a table");
    sc->add_option("--plot", mill.plot_path, "Write a plot (PNG)");
    sc->add_flag("--damped", mill.damped, "Also with the damping controller's loop closed, overlaid");
    sc->add_option("--controller", mill.controller_path,
                   "Damping configuration to use instead of the job's (compare compensators)")->check(CLI::ExistingFile);
  }
  lobes->add_option("--rpm", mill.rpm, "Limiting depth at these speeds by the direct test (the spindle speed is always included)");

  CLI11_PARSE(app, argc, argv);
  if (lobes->parsed()) return robodamp::apps::run_lobes(mill);
  if (sle->parsed()) return robodamp::apps::run_sle(mill);
  if (run->parsed()) {
    run_opts.config_path = config_path;
    if (!clock.empty()) run_opts.clock = clock == "wall" ? robodamp::config::ClockKind::kWall : robodamp::config::ClockKind::kVirtual;
    return robodamp::apps::run_loop(run_opts);
  }
  if (monitor->parsed() || request->parsed()) {
    if (!dds_config.empty()) {
      try {
        const auto cfg = robodamp::config::load_config_file(dds_config);
        if (cfg.dds && (*monitor->get_option("--domain")).count() == 0 && (*request->get_option("--domain")).count() == 0)
          dds_opts.domain_id = cfg.dds->domain_id;
        if (cfg.dds && dds_transport == "default") dds_opts.transport = cfg.dds->transport;
      } catch (const robodamp::config::ConfigError& e) {
        std::cerr << e.what() << '\n';
        return 2;
      }
    }
    if (dds_transport == "udp_loopback") dds_opts.transport = robodamp::config::DdsTransport::kUdpLoopback;
    if (dds_transport == "shared_memory") dds_opts.transport = robodamp::config::DdsTransport::kSharedMemory;
    try {
      return monitor->parsed() ? robodamp::apps::run_monitor(dds_opts) : robodamp::apps::run_request(dds_opts, req_opts);
    } catch (const std::exception& e) {
      std::cerr << e.what() << '\n';
      return 1;
    }
  }
  if (plant->parsed()) {
    plant_opts.config_path = config_path;
    if (!pacing.empty()) plant_opts.pacing = pacing == "lockstep" ? robodamp::config::HilPacing::kLockstep : robodamp::config::HilPacing::kRealtime;
    return robodamp::apps::run_plant(plant_opts);
  }
  if (replay->parsed()) return robodamp::apps::run_replay(recording);
  if (csv->parsed()) return robodamp::apps::run_csv(recording, csv_out);
  if (bench->parsed()) return run_bench(config_path, json_path, plot_dir);
  if (analyze->parsed()) return run_analyze(config_path, json, plot_dir);
  if (filters->parsed()) return run_filters(config_path, freq_hz, json, plot);
  if (check->parsed()) return run_check_config(check_path);
  return 1;
}
