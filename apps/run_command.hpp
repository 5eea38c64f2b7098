// `robodamp run` (the deployment entry point; the simulated backend paces the simulated plant in real
// time), `robodamp replay` (a recording through the same controller, bit for bit) and `robodamp csv`.
#pragma once

#include <optional>
#include <string>

#include "config/config.hpp"

namespace robodamp::apps {

struct RunOptions {
  std::string config_path;
  double duration_s{10.0};
  std::string record_path;
  std::string json_path;
  std::string histogram_path;  // wake-up latency histogram in cyclictest's --histfile format
  std::optional<config::ClockKind> clock;
  double impact_every_s{2.0};
};

// The configuration at path, or nothing after printing every problem to stderr (exit status 2).
[[nodiscard]] std::optional<config::Config> load_config_or_report(const std::string& path);

// Exit codes: 0 ended safe (disarmed, or shut down by a signal), 2 configuration error, 4 ended in a
// fault trip, 1 other error (recording).
[[nodiscard]] int run_loop(const RunOptions& o);
// 0 bit-exact, 1 mismatches, 2 unreadable recording.
[[nodiscard]] int run_replay(const std::string& path);
[[nodiscard]] int run_csv(const std::string& path, const std::string& out_path);

}  // namespace robodamp::apps
