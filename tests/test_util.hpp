#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <thread>
#include <sstream>
#include <stdexcept>
#include <string>

#include "config/config.hpp"
#include "analysis/chain_design.hpp"
#include "config/yaml_edit.hpp"

namespace robodamp::test {

// A directory of the test's own under the process's temporary directory (tests/test_main.cpp), removed
// with everything in it when the object goes.
struct ScratchDir {
  std::string path;
  explicit ScratchDir(const std::string& name) {
    std::string tmpl = (std::filesystem::temp_directory_path() / ("robodamp-" + name + "-XXXXXX")).string();
    path = mkdtemp(tmpl.data());
  }
  ~ScratchDir() { std::filesystem::remove_all(path); }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] std::string file(const std::string& f) const { return path + "/" + f; }
};

struct CommandResult {
  int status;       // exit status, -1 when the process did not exit
  std::string out;  // stdout and stderr together
};

#ifdef ROBODAMP_BINARY
// `robodamp ARGS`, its output and exit status.
inline CommandResult run_robodamp(const std::string& args) {
  FILE* p = popen((std::string(ROBODAMP_BINARY) + " " + args + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int rc = pclose(p);
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, out};
}
#endif

// A file of this source tree by its path under the root. Appended, not a chain of +: GCC 12 warns a false
// -Warray-bounds on std::string(ROBODAMP_SOURCE_DIR) + ... at -O1 with the precompiled header
// (cmake/build_speed.cmake).
inline std::string source_path(const std::string& rel) {
  std::string path = ROBODAMP_SOURCE_DIR;
  return path.append("/").append(rel);
}

inline std::string preset(const std::string& name) { return source_path("config/presets/" + name + ".yaml"); }

inline analysis::ChainDesign design_preset(const std::string& name, double rate_hz = 0.0) {
  config::Config c = config::load_config_file(preset(name));
  if (rate_hz > 0.0) c.loop.rate_hz = rate_hz;
  return analysis::design_chain(c);
}

// tuned_vertical.yaml as `robodamp tune` first wrote it (before the quiet-command constraint): a stable
// loop (gain margin 12 dB) whose compensator has a slow, lightly damped pole pair; the instability
// detector's floor at its default (vertical_c1.yaml now raises it for C1).
inline config::Config slow_pole_vertical() {
  const config::Config base = config::load_config_file(preset("vertical_c1"));
  const std::string entry =
      "{kind: compensator, model: rational, numerator: [0.027404602793258317, 0.42320583618593827, 341.23272947339467, "
      "1463.5814931482228], denominator: [0.074624991310120958, 0.43650875239379344, 0.96951995294320148, 1]}";
  return config::parse_config(
      config::edit_yaml(base.yaml_text, {{{"controller", "gain_ns_per_m"}, YAML::Node("6040.303629")},
                                         {{"controller", "polarity"}, YAML::Node("-1")},
                                         {{"controller", "chain", std::size_t{5}}, YAML::Load(entry)},
                                         {{"supervision", "instability_floor_v"}, YAML::Node("0.02")}})
          .text,
      "slow_pole_vertical");
}

// A mode in modal-stiffness form (Eq. 1 with a stiffness instead of a residue).
inline config::ModeConfig stiffness_mode(double fn_hz, double zeta, double k_n_per_m) {
  config::ModeConfig m;
  m.form = config::ModeForm::kStiffness;
  m.natural_freq_hz = fn_hz;
  m.damping_ratio = zeta;
  m.stiffness_n_per_m = k_n_per_m;
  return m;
}

// Every occurrence of from in s replaced; an edit that finds nothing is a broken test, not a silent no-op.
inline void replace_or_throw(std::string& s, const std::string& from, const std::string& to) {
  if (s.find(from) == std::string::npos) throw std::runtime_error("the test's edit finds no '" + from + "'");
  for (auto p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size())) s.replace(p, from.size(), to);
}

inline std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The command a file's header records on the line after `header` ("#   robodamp COMMAND ... --out FILE"), run
// again from the source folder with --out dir/name.yaml (its output in dir/log.txt). Returns that path, or ""
// with what went wrong in why.
inline std::string rerun_recorded_command(const std::string& text, const std::string& header,
                                          const std::string& command, const std::string& dir, const std::string& name,
                                          std::string& why) {
  const auto at = text.find(header);
  if (at == std::string::npos) return why = "no \"" + header + "\" in the file", "";
  std::istringstream lines(text.substr(at));
  std::string first, line;
  std::getline(lines, first);
  std::getline(lines, line);
  if (line.rfind("#   robodamp " + command + " ", 0) != 0)
    return why = "not a robodamp " + command + " command: " + line, "";
  const std::string out = dir + "/" + name + ".yaml";
  line =
      std::regex_replace(line.substr(std::string("#   robodamp ").size()), std::regex(" --out \\S+$"), " --out " + out);
  const std::string run =
      "cd " + std::string(ROBODAMP_SOURCE_DIR) + " && " + ROBODAMP_BINARY + " " + line + " > " + dir + "/log.txt 2>&1";
  if (std::system(run.c_str()) != 0) return why = run + "\n" + read_file(dir + "/log.txt"), "";
  return out;
}

// Wrapped phase difference in degrees.
inline double phase_diff_deg(double a, double b) {
  double d = a - b;
  while (d > 180.0) d -= 360.0;
  while (d <= -180.0) d += 360.0;
  return d;
}

// How many times slower than a plain build this run's processes are: ROBODAMP_TEST_PACE, which
// scripts/sanitize.sh sets (4 under ThreadSanitizer, 2 under AddressSanitizer), 1 otherwise. A test whose
// scenario needs one process to keep pace with another (a monitor's analysis within a robot's dwell in
// virtual time) stretches the scenario by it; nothing is asserted about time.
inline double pace() {
  const char* v = std::getenv("ROBODAMP_TEST_PACE");
  if (v == nullptr || *v == '\0') return 1.0;
  char* end = nullptr;
  const double p = std::strtod(v, &end);
  if (*end != '\0' || !(p >= 1.0 && p <= 20.0))
    throw std::invalid_argument(std::string("ROBODAMP_TEST_PACE = '") + v + "': expected a number in [1, 20]");
  return p;
}

// Polls pred every millisecond until it holds or timeout_s passes (for threads and other processes;
// the timeout only bounds a failing test, nothing is asserted about how long it took).
inline bool eventually(const std::function<bool()>& pred, double timeout_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return pred();
}

// Until the file at `path` (a process's log) contains `text`, or timeout_s passes.
inline bool file_says(const std::string& path, const std::string& text, double timeout_s) {
  return eventually([&] { return read_file(path).find(text) != std::string::npos; }, timeout_s);
}

}  // namespace robodamp::test
