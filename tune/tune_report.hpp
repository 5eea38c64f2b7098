// What `robodamp tune` reports (docs/tuning.md): the plants a candidate is tuned for, the hand designs
// compared with the tuned one on each, as the lines a person reads and the report's JSON, the lobes plot,
// the tuned loop's robustness and the verification of its promises. Off the real-time path.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/compensator_search.hpp"
#include "tune/tuned_file.hpp"
#include "tune/verification.hpp"

namespace robodamp::tune {

[[nodiscard]] nlohmann::json candidate_json(const Candidate& c);
[[nodiscard]] nlohmann::json evaluation_json(const Evaluation& e);
// With each plant's evaluation under "per_plant" when there are several.
[[nodiscard]] nlohmann::json evaluation_json_with_plants(const Evaluation& e);

// One evaluation as a line of the comparison table ("  C2     K ...\n").
[[nodiscard]] std::string evaluation_row(const std::string& name, const Evaluation& e);

// The plants a candidate is tuned for: each configuration, and with shift_pct each of them with its modes
// shifted down and up by that ("PATH (modes -5 %)"). Throws config::ConfigError for a file that does not load.
[[nodiscard]] std::vector<Evaluator> tuning_plants(const std::vector<std::string>& config_paths,
                                                   std::optional<double> shift_pct,
                                                   const std::optional<config::MillingConfig>& job,
                                                   const TuneSettings& settings);

// A design compared on a plant: its name (C1, C2, C3, tuned), its configuration and its evaluation.
struct ComparedDesign {
  std::string name;
  config::Config cfg;
  Evaluation e;
};

// The plant's hand designs (C1, C2, C3 at the configured gain and the recommended polarity) when asked,
// and the tuned one last.
[[nodiscard]] std::vector<ComparedDesign> compare_designs(const Evaluator& p, const Evaluation& tuned,
                                                          bool hand_designs);

// One plant's comparison: the rows, the damped floor in each interval between the open loop's lobe peaks,
// the improvement at each mode. Returns the lines and adds the plant's JSON to out under its name.
[[nodiscard]] std::string plant_report(const Evaluator& p, const std::vector<ComparedDesign>& rows,
                                       nlohmann::json& out);

// The open loop's lobes with each compared design's (sampled-loop SDM) into png_path: an empty string, or
// why the plot failed.
[[nodiscard]] std::string plot_compared_lobes(const Evaluator& p, const std::vector<ComparedDesign>& rows,
                                              const std::string& png_path);

// How far the tuned loop holds as the modes move (a weak point is a warning): the line, and
// report["robustness"].
[[nodiscard]] std::string robustness_report(const config::Config& tuned, nlohmann::json& report);

// The tuned file's promises verified on the job: the lines, and report["verified"].
[[nodiscard]] std::string verification_report(const Verification& v, nlohmann::json& report);

// How far the loop holds as the modes move together (tune/robustness.hpp), into report["robustness"]; its
// line, with a warning under +-kRobustShiftWarnPct.
[[nodiscard]] std::string robustness_section(const config::Config& cfg, nlohmann::json& report);

// The search's report on `out` as it goes (each plant's comparison with the hand designs, the first plant's
// compared lobes into plot_path when a job is given and it is not empty, the worst over the plants) and its JSON
// (the configurations, the best with each plant's, the comparisons, the history). Throws std::runtime_error
// when the plot cannot be written.
[[nodiscard]] nlohmann::json search_report(const TuneCommand& cmd, const std::vector<Evaluator>& plants,
                                           const TuneResult& r, bool has_job, const std::string& plot_path,
                                           std::FILE* out);

}  // namespace robodamp::tune
