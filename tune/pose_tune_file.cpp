#include "tune/pose_tune_file.hpp"

#include <filesystem>
#include <fstream>
#include <regex>

#include <yaml-cpp/yaml.h>

#include "analysis/pose_schedule.hpp"
#include "config/file_paths.hpp"
#include "config/number_range.hpp"
#include "config/yaml_edit.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::tune {

namespace {

YAML::Node numbers(const std::vector<double>& v) {
  YAML::Node n(YAML::NodeType::Sequence);
  n.SetStyle(YAML::EmitterStyle::Flow);
  for (double x : v) n.push_back(exact(x));
  return n;
}

YAML::Node region_node(const config::PoseRegionConfig& r) {
  YAML::Node n(YAML::NodeType::Map);
  n["name"] = r.name;
  n["min_deg"] = numbers(r.min_deg);
  n["max_deg"] = numbers(r.max_deg);
  if (r.gain_ns_per_m) n["gain_ns_per_m"] = exact(*r.gain_ns_per_m);
  if (r.polarity) n["polarity"] = *r.polarity > 0 ? "+1" : "-1";
  if (r.match_freq_hz) n["match_freq_hz"] = exact(*r.match_freq_hz);
  if (r.compensator) {
    YAML::Node c(YAML::NodeType::Map);
    c["numerator"] = numbers(r.compensator->numerator);
    c["denominator"] = numbers(r.compensator->denominator);
    n["compensator"] = c;
  }
  return n;
}

}  // namespace

std::vector<TunedRegion> WorkspaceTune::chosen() const {
  if (best == 0) return {robust};
  if (best == 1) return scheduled;
  return {};
}

WorkspaceTune tune_workspace(const PoseTuneInput& in, const std::vector<NamedPose>& held_out,
                             const std::optional<config::MillingConfig>& job, const PoseTuneSettings& s, int map_points,
                             const PoseTuneProgress& progress) {
  WorkspaceTune w;
  w.robust = tune_robust(in, s, progress);
  w.scheduled = tune_schedule(in, w.robust, s, progress);
  w.scores = score_on_map(in, workspace_map(in, map_points, held_out),
                          {{"robust", schedule_of(*in.cell.pose_schedule, {w.robust})},
                           {"scheduled", schedule_of(*in.cell.pose_schedule, w.scheduled)},
                           {"as given", *in.cell.pose_schedule}},
                          job, progress);
  w.best = better_controller(w.scores, s.worse_mode_tolerance_pct);
  return w;
}

std::string write_pose_tuned_config(const config::Config& cell, const std::vector<TunedRegion>& chosen,
                                    const std::string& model_path, const std::string& out_path,
                                    const std::string& header) {
  std::vector<config::PoseRegionConfig> regions;
  for (const auto& r : chosen) regions.push_back(r.region);
  return write_pose_regions(cell, regions, model_path, out_path, header);
}

std::string write_pose_regions(const config::Config& cell, const std::vector<config::PoseRegionConfig>& chosen,
                               const std::string& model_path, const std::string& out_path, const std::string& header) {
  std::vector<config::YamlEdit> edits;
  if (!chosen.empty()) {
    YAML::Node regions(YAML::NodeType::Sequence);
    for (const auto& r : chosen) regions.push_back(region_node(r));
    edits.push_back({{"pose_schedule", "regions"}, regions});
  }
  if (!model_path.empty())
    edits.push_back({{"pose_schedule", "model"}, YAML::Node(std::filesystem::absolute(model_path).string())});
  config::EditedYaml e = config::edit_yaml(cell.yaml_text, edits);
  // The regions' old comment describes the regions that were there.
  if (!chosen.empty()) e.text = std::regex_replace(e.text, std::regex(R"(\n(  regions:)[ \t]*#[^\n]*)"), "\n$1");
  const std::string text = header + config::rebase_file_paths(e.text, cell.source, out_path).text;
  if (const auto parent = std::filesystem::path(out_path).parent_path(); !parent.empty())
    std::filesystem::create_directories(parent);
  const std::string check = out_path + ".check.yaml";
  { std::ofstream(check) << text; }
  try {
    (void)analysis::analyse_pose_schedule(config::load_config_file(check));
  } catch (...) {
    std::filesystem::remove(check);
    throw;
  }
  std::filesystem::rename(check, out_path);
  return text;
}

std::string pose_tune_command_line(const PoseTuneCommand& a) {
  std::string c = "robodamp pose tune --config " + a.config_path;
  if (!a.model_path.empty()) c += " --model " + a.model_path;
  if (!a.measurements.empty()) {
    c += " --measurements";
    for (const auto& m : a.measurements) c += " " + m;
  }
  if (!a.hold_out.empty()) {
    c += " --hold-out";
    for (const auto& h : a.hold_out) c += " " + h;
  }
  if (!a.job_path.empty()) c += " --job " + a.job_path;
  c += " --evaluations " + std::to_string(a.evaluations) + " --polish " + std::to_string(a.polish) + " --max-regions " +
       std::to_string(a.max_regions) + " --map-points " + std::to_string(a.map_points) + " --overlap-deg " +
       config::format_number(a.overlap_deg) + " --worse-mode-pct " + config::format_number(a.worse_mode_pct) +
       " --seed " + std::to_string(a.seed) + " --out " + a.out_path;
  return c;
}

}  // namespace robodamp::tune
