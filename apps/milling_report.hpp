// What `robodamp lobes` and `robodamp sle` share: the milling job's options, the reports (what a cut
// buys with and without active damping, docs/milling.md) as JSON, a table and a plot.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "config/milling_config.hpp"
#include "milling/cut_verdict.hpp"

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

// --pose into the job: every pose part takes the joints, checked against its model's travel. Throws
// config::ConfigError when the job has no pose part or the pose does not fit.
void apply_pose(config::MillingConfig& cfg, const MillingOptions& o);

// `command` is "lobes" or "sle" (the plot's file name in --plot-dir).
void add_milling_options(Registry& r, CLI::App* sub, MillingOptions& o, const std::string& command);

// The job's structure by name (empty: the job's choice), every controller part's damping configuration
// replaced by controller_path when given. Throws config::ConfigError for an unknown name.
[[nodiscard]] config::StructureConfig selected_structure(const config::MillingConfig& cfg, const std::string& structure,
                                                         const std::string& controller_path);

// Throw config::ConfigError for a job or an option that does not fit it.
[[nodiscard]] nlohmann::json lobes_report(const config::MillingConfig& cfg, const MillingOptions& o);
[[nodiscard]] nlohmann::json sle_report(const config::MillingConfig& cfg, const MillingOptions& o);
// The table or JSON on stdout, then the plot: 0, or 1 when the plot failed.
[[nodiscard]] int print_lobes(const nlohmann::json& r, const MillingOptions& o);
// What the damper does for a cut (milling/cut_verdict.hpp) as the reports' JSON "cut" block.
[[nodiscard]] nlohmann::json cut_verdict_json(const milling::CutVerdict& v);
[[nodiscard]] int print_sle(const nlohmann::json& r, const MillingOptions& o);

}  // namespace robodamp::apps
