// What `robodamp pose tune` reports (docs/pose_dynamics.md): the robust set and the scheduled regions with their
// worst poses, the workspace map scored for each controller, the comparison and the one chosen; text and JSON.
// Off the real-time path.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "config/milling_config.hpp"
#include "tune/pose_tune.hpp"
#include "tune/pose_tune_file.hpp"

namespace robodamp::tune {

struct PoseTuneReport {
  nlohmann::json json;
  std::string text;
};

// config_path, job_path: as given (the report names them); held_out: the poses scored, not tuned at.
[[nodiscard]] PoseTuneReport pose_tune_report(const std::string& config_path, const PoseTuneInput& in,
                                              std::size_t held_out, const WorkspaceTune& w, const PoseTuneSettings& s,
                                              const std::optional<config::MillingConfig>& job,
                                              const std::string& job_path);

}  // namespace robodamp::tune
