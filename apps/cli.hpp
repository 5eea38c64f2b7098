// The command line: each subcommand lives in its own apps/<name>_command.cpp, where a register_<name>()
// adds its options and its handler; main() only calls dispatch(). The machinery they share (the registry's
// range-checked numbers, --json, --plot-dir, deprecated spellings, the report's output) is command_line/.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "command_line/registry.hpp"
#include "command_line/report_output.hpp"
#include "config/file_paths.hpp"
#include "config/number_text.hpp"

namespace robodamp::apps {

// The commands' defaults, found in the data folders (an installed /usr/share/robodamp, else this tree's).
[[nodiscard]] inline std::string default_cell_config() { return config::shipped_file("presets/horizontal_c2.yaml"); }
[[nodiscard]] inline std::string default_job() {
  return config::shipped_file("milling/industrial_robot_aluminium.yaml");
}

using command_line::emit_json;
using command_line::JsonOut;
using command_line::plot_file;
using command_line::print_report;
using command_line::Registry;
using config::parse_number;  // config/number_text.hpp

// `robodamp --version`: robodamp's version and commit, and the dependencies it was built against.
[[nodiscard]] std::string version_text();

// Parses and runs a command line. 0 for --help and --version; 2 for a bad command line (message on
// stderr); the exit statuses are in docs/cli.md.
[[nodiscard]] int dispatch(int argc, const char* const* argv);

// Registration of each subcommand (apps/<name>_command.cpp).
void register_filters(Registry& r);
void register_check_config(Registry& r);
void register_analyze(Registry& r);
void register_bench(Registry& r);
void register_run(Registry& r);
void register_plant(Registry& r);
void register_monitor(Registry& r);
void register_request(Registry& r);
void register_dashboard(Registry& r);
void register_replay(Registry& r);
void register_csv(Registry& r);
void register_lobes(Registry& r);
void register_sle(Registry& r);
void register_cut(Registry& r);
void register_identify(Registry& r);
void register_measure(Registry& r);
void register_commission(Registry& r);
void register_pose(Registry& r);
void register_tune(Registry& r);
void register_schedule(Registry& r);
void register_chatter(Registry& r);

}  // namespace robodamp::apps
