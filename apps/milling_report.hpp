// What `robodamp lobes` and `robodamp sle` share: the milling job's options and printing the reports the
// milling library makes (milling/study_report.hpp) as JSON, a table and a plot.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "config/milling_config.hpp"
#include "milling/study_report.hpp"

namespace robodamp::apps {

struct MillingOptions {
  std::string job_path{default_job()};  // --job (the deprecated --config)
  std::string structure;                // empty: the configuration's choice
  JsonOut json;
  std::string plot_dir;          // --plot-dir: DIR/lobes.png or DIR/sle.png
  std::string plot_path;         // the deprecated --plot FILE (PNG)
  bool damped{false};            // also with the controller's loop closed, overlaid
  std::vector<double> rpm;       // lobes: extra speeds for the direct test
  std::string controller_path;   // replaces every controller part's damping configuration
  std::string method{"sdm"};     // lobes: sdm (semi-discretization of what runs: the promise) or zoa (preview)
  std::vector<double> pose_deg;  // replaces the joints of every robot pose part (docs/pose_dynamics.md)
};

// The study's part of the options.
[[nodiscard]] milling::StudyOptions study_options(const MillingOptions& o);

// `command` is "lobes" or "sle" (the plot's file name in --plot-dir).
void add_milling_options(Registry& r, CLI::App* sub, MillingOptions& o, const std::string& command);

// The reports with the study's progress on stderr (a many-mode open loop takes minutes). Throw
// config::ConfigError for a job or an option that does not fit it.
[[nodiscard]] nlohmann::json lobes_report(const config::MillingConfig& cfg, const MillingOptions& o);
[[nodiscard]] nlohmann::json sle_report(const config::MillingConfig& cfg, const MillingOptions& o);
// The table or JSON on stdout, then the plot: 0, or 1 when the plot failed.
[[nodiscard]] int print_lobes(const nlohmann::json& r, const MillingOptions& o);
[[nodiscard]] int print_sle(const nlohmann::json& r, const MillingOptions& o);

}  // namespace robodamp::apps
