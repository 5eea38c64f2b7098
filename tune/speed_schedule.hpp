// A controller that follows the spindle (robodamp schedule; docs/tuning.md, "A controller that follows the
// spindle"): for a cell and its milling job, which controller and K give the deepest limit at each spindle
// speed, K = 0 (the open loop) included, so that the damped limit is never below the open loop's.
//
// Every depth is the accurate method's (milling/accurate_stability.hpp: SDM open loop, the sampled loop's
// semi-discretization damped), at the speeds the sampled loop runs (a whole number of loop periods per tooth
// period). Candidates: each controller (the cell's own, and the chains of other configuration files) at
// gains log-spaced up to the largest K that keeps the gain, phase and delay margins. On a grid of speeds
// every candidate is computed and the deepest chosen (the open loop unless a damped one beats it by
// gain_min_pct; the previous speed's kept while within keep_within_pct of the best, for fewer bands). Bands
// change halfway between grid speeds. Then the bands are checked at two speeds between each pair of grid
// speeds: a check where the band's candidate is worse than the open loop becomes a grid speed of its own
// (every candidate computed there, its band split off), for refine_rounds rounds; a check still worse after the
// last round gets a band of the open loop's (K = 0) around it, which only shrinks its neighbours' bands. What
// the summary finds worse (between the checks) is reported, never hidden. Off the real-time path.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/loop_model.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "config/yaml_edit.hpp"

namespace robodamp::tune {

struct ScheduleSettings {
  double gain_margin_min_db{6.0};
  double phase_margin_min_deg{45.0};
  double delay_margin_min_ms{0.5};
  int gains_per_controller{6};      // log-spaced from top / 16 to the top gain (the largest with the margins)
  int speeds{0};                    // the grid over the job's lobes range; 0: time_domain.sdm_points
  double gain_min_pct{1.0};         // a damped candidate is chosen where it beats the open loop by this
  double keep_within_pct{2.0};      // the previous speed's candidate is kept while this close to the best
  double worse_tolerance_pct{0.5};  // below the open loop by more than this is "worse" (the depths are to 0.1 %)
  int refine_rounds{3};
  std::size_t threads{0};  // 0: one per core
  // Called as the depths come in: what is being computed, done, of.
  std::function<void(const std::string& what, std::size_t done, std::size_t of)> progress;
};

// A controller a band may run: the cell's own (file empty) or another configuration's chain.
struct ScheduleController {
  std::string file;                                    // as given; empty: the cell's own controller
  std::optional<config::SpeedControllerConfig> entry;  // another file's: what the schedule writes for it
  config::Config config;                               // the cell with this controller
  std::shared_ptr<const analysis::LoopModel> model;
  int polarity{1};
  std::optional<double> k_max_ns_per_m;  // the discrete loop's; none: stable to the gain limit
  double top_gain_ns_per_m{0.0};         // the largest K with every margin (0: none)
  std::string top_gain_reason;           // which limit set it
  std::vector<double> gains;             // tried, ascending
};

// Candidate 0 is the open loop (K = 0); the others a controller at a gain.
struct ScheduleCandidate {
  std::size_t controller{0};
  double gain_ns_per_m{0.0};
};

struct ScheduleSpeed {
  double rpm{0.0};  // as the sampled loop runs it
  int ticks_per_tooth{0};
  bool grid{false};  // every candidate computed here (else a check between grid speeds)
  double open_mm{0.0};
  double fixed_mm{0.0};  // the cell as configured (its controller at controller.gain_ns_per_m)
  double scheduled_mm{0.0};
  std::size_t candidate{0};  // the schedule's here
  std::size_t band{0};
};

// What the schedule does for the job, in the machinist's terms (every depth the accurate method's).
struct ScheduleSummary {
  std::size_t speeds{0}, grid_speeds{0};
  double open_min_mm{0.0}, open_min_rpm{0.0};
  double fixed_min_mm{0.0}, fixed_min_rpm{0.0};
  double scheduled_min_mm{0.0}, scheduled_min_rpm{0.0};
  double fixed_mean_ratio{0.0}, scheduled_mean_ratio{0.0};    // over the speeds, x the open loop
  double fixed_worse_share{0.0}, scheduled_worse_share{0.0};  // of the speeds below the open loop (tolerance)
  double fixed_worst_ratio{0.0}, fixed_worst_rpm{0.0};
  double scheduled_worst_ratio{0.0}, scheduled_worst_rpm{0.0};
  double scheduled_better_share{0.0};  // above the open loop by gain_min_pct
  // At the job's spindle speed (cut.spindle_rpm), where the sampled loop runs it.
  double job_rpm{0.0}, job_open_mm{0.0}, job_fixed_mm{0.0}, job_scheduled_mm{0.0};
};

// A damped limit the cut in time did not hold at 0.95 x (tune/schedule_in_time.hpp).
struct LoweredLimit {
  double rpm{0.0};
  std::size_t candidate{0};
  double accurate_mm{0.0};  // the accurate method's
  double time_mm{0.0};      // the time domain's critical depth there
  bool kept{false};         // still run there (found in the last pass), at time_mm; else another candidate runs there
};

struct SpeedSchedule {
  std::string method;  // of the depths
  ScheduleSettings settings;
  std::vector<ScheduleController> controllers;
  std::vector<ScheduleCandidate> candidates;
  std::vector<config::SpeedBandConfig> bands;  // controller: index into controllers
  std::vector<ScheduleSpeed> speeds;           // ascending: the grid and the checks
  std::size_t refined_speeds{0};               // checks that failed and became grid speeds
  // The damped limits of the schedule's speeds checked in time (tune/schedule_in_time.hpp): cuts at 0.95 x the
  // limit, and of them those that chattered (that candidate not used there: the speed chosen again).
  std::size_t limits_in_time{0}, lowered_in_time{0};
  std::vector<LoweredLimit> lowered;
  // Bands with a depth_limit_mm (a limit in time below the accurate method's).
  [[nodiscard]] std::size_t limited_bands() const {
    std::size_t n = 0;
    for (const auto& b : bands) n += b.depth_limit_mm ? 1U : 0U;
    return n;
  }
  // Damped limits computed, and of them those capped where the cut's forced vibration drives the actuator to
  // its force limit (milling/forced_command.hpp): the linear stability analysis assumes an unlimited actuator.
  std::size_t damped_limits{0}, capped_limits{0};
  ScheduleSummary summary;
  std::vector<std::string> notes;
};

// Another controller a band may run, and where it came from (a file, "C1 hand design", ...).
struct NamedController {
  std::string name;
  config::SpeedControllerConfig controller;
};
// The controller of another configuration file (its compensator block, polarity, match frequency).
[[nodiscard]] NamedController controller_of_file(const std::string& path);

// cell: the configuration scheduled (its own controller is controller 0); others: the compensators a band may
// run instead, in cell's chain; job and structure: the cut, whose controller parts take each candidate's loop.
[[nodiscard]] SpeedSchedule schedule_speeds(const config::Config& cell, const std::vector<NamedController>& others,
                                            const config::MillingConfig& job, const config::StructureConfig& structure,
                                            const ScheduleSettings& settings);

// The schedule as the configuration's controller.speed_schedule, in the cell's text (config/yaml_edit.hpp),
// other controllers' paths relative to the cell's folder (config::rebase_file_paths moves them with the
// file). Throws std::invalid_argument when the text cannot be edited to read back.
// The text without its controller.speed_schedule block (the key's line and every line indented deeper): a file
// scheduled again, or tuned (the schedule chose K for the controller the tune replaces).
[[nodiscard]] std::string without_schedule_block(const std::string& text);
// And without the header robodamp schedule wrote on top of it (from "# robodamp schedule wrote" to its "# Everything
// else is ...'s, whose header follows." and the "#" line after), when the text starts with one.
[[nodiscard]] std::string without_schedule(const std::string& text);

[[nodiscard]] config::EditedYaml scheduled_config_text(const config::Config& cell, const SpeedSchedule& s);

}  // namespace robodamp::tune
