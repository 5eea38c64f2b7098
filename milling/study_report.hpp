// The reports of the milling studies `robodamp lobes` and `robodamp sle` print (docs/milling.md): what a
// cut buys with and without active damping, as the report's JSON, the table a person reads and the plot;
// and the cut verdict (milling/cut_verdict.hpp) as the reports' "cut" block. Off the real-time path.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/milling_config.hpp"
#include "milling/cut_verdict.hpp"

namespace robodamp::milling {

// What a study is asked for beside the job.
struct StudyOptions {
  std::string structure;        // empty: the job's `structure`
  std::string controller_path;  // replaces every controller part's damping configuration (empty: none)
  bool damped{false};           // also with the controller's loop closed, overlaid
  std::vector<double> rpm;      // lobes: extra speeds for the direct test (the job's spindle speed is added)
  std::string method{"sdm"};    // lobes: sdm (semi-discretization of what runs: the promise) or zoa (preview)
};

// A long study's progress, one line at a time, for a person (the command line writes it to stderr).
using StudyProgress = std::function<void(const std::string& line)>;

// The job's structure by name (empty: the job's choice), every controller part's damping configuration
// replaced by controller_path when given. Throws config::ConfigError for an unknown name.
[[nodiscard]] config::StructureConfig selected_structure(const config::MillingConfig& cfg, const std::string& structure,
                                                         const std::string& controller_path);

// The joints into every pose part of the job (none: unchanged), checked against its model's travel. Throws
// config::ConfigError when the job has no pose part or the pose does not fit.
void apply_pose(config::MillingConfig& cfg, const std::vector<double>& pose_deg);

// The studies' reports. Throw config::ConfigError for a job or an option that does not fit it.
[[nodiscard]] nlohmann::json lobes_report(const config::MillingConfig& cfg, const StudyOptions& o,
                                          const StudyProgress& progress = {});
[[nodiscard]] nlohmann::json sle_report(const config::MillingConfig& cfg, const StudyOptions& o);

// A report as the table a person reads.
[[nodiscard]] std::string lobes_table(const nlohmann::json& report);
[[nodiscard]] std::string sle_table(const nlohmann::json& report);

// A report's plot through gnuplot into png_path: an empty string, or why it failed.
[[nodiscard]] std::string plot_lobes(const nlohmann::json& report, const std::string& png_path);
[[nodiscard]] std::string plot_sle(const nlohmann::json& report, const std::string& png_path);

// What the damper does for a cut as the reports' JSON "cut" block.
[[nodiscard]] nlohmann::json cut_verdict_json(const CutVerdict& v);

// The cell's job (spindle.job) at a spindle speed: its open and damped limits by the accurate method (the
// cell's live stability, milling/live_stability.hpp), each with its method, as analyze's "job_limits" block;
// null without a job.
[[nodiscard]] nlohmann::json job_limits_json(const config::Config& cfg, double rpm);

}  // namespace robodamp::milling
