// Tuning over a workspace and the file it writes (robodamp pose tune, commission --along-path;
// docs/pose_dynamics.md, "Tuning across the workspace"): the robust set and the schedule drawn from the
// data (tune/pose_tune.hpp), both scored beside the configuration's own schedule on the workspace map
// (tune/pose_score.hpp), the better chosen; and the configuration with the chosen regions (and the model they
// were tuned on) written in whatever YAML style the configuration is, read back and its schedule analysed
// before it replaces anything. Off the real-time path.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/pose_score.hpp"
#include "tune/pose_tune.hpp"

namespace robodamp::tune {

struct WorkspaceTune {
  TunedRegion robust;
  std::vector<TunedRegion> scheduled;
  MapScores scores;     // controllers: robust, scheduled, "as given" (the configuration's own schedule)
  std::size_t best{0};  // into scores.controllers
  // The regions to write: the robust one, the scheduled ones, or none (the configuration's own schedule won).
  [[nodiscard]] std::vector<TunedRegion> chosen() const;
  [[nodiscard]] const ControllerScore& best_score() const { return scores.controllers[best]; }
};

// map_points: the workspace map's grid per joint (workspace_map); held_out: poses scored, not tuned at.
[[nodiscard]] WorkspaceTune tune_workspace(const PoseTuneInput& in, const std::vector<NamedPose>& held_out,
                                           const std::optional<config::MillingConfig>& job, const PoseTuneSettings& s,
                                           int map_points, const PoseTuneProgress& progress = {});

// The cell's text with the chosen regions (none: its regions stay as written) and pose_schedule.model set to
// model_path (empty: as it is), its relative paths rebased to out_path, behind header; written to out_path
// once it reads back and every region's set analyses over its grid. Returns the text written. Throws
// config::ConfigError (the check) or std::invalid_argument (the edit).
std::string write_pose_tuned_config(const config::Config& cell, const std::vector<TunedRegion>& chosen,
                                    const std::string& model_path, const std::string& out_path,
                                    const std::string& header);
// The same with the regions as the configuration holds them (a region's optional keys written where set).
std::string write_pose_regions(const config::Config& cell, const std::vector<config::PoseRegionConfig>& regions,
                               const std::string& model_path, const std::string& out_path, const std::string& header);

// What `robodamp pose tune` was asked (its options as given): the written file's header repeats it as a command.
struct PoseTuneCommand {
  std::string config_path;  // the cell, with a pose_schedule
  std::string model_path;   // the pose-indexed model; default pose_schedule.model
  std::vector<std::string> measurements, hold_out;
  std::string job_path;
  int evaluations{60}, polish{30}, max_regions{4}, map_points{9}, seed{1};
  double overlap_deg{4.0};
  double worse_mode_pct{0.0};  // a mode in the damping band this much worse than open loop still serves
  std::string out_path;
};

// The command that writes the file again.
[[nodiscard]] std::string pose_tune_command_line(const PoseTuneCommand& c);

}  // namespace robodamp::tune
