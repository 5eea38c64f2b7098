#include "commission/pose_measurements.hpp"

#include <cctype>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "config/config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::commission {

namespace fs = std::filesystem;

std::vector<config::RobotPoseConfig> read_measurement_poses(const std::string& config_path,
                                                            const std::string& poses_file) {
  const config::Config cfg = config::load_config_file(config_path);
  if (cfg.can)
    throw config::ConfigError(
        {config::Problem{cfg.source,
                         {},
                         "can",
                         "is set: --poses measures one pose after the other without stopping, which "
                         "only the simulated plant can follow; on hardware move the robot and run "
                         "robodamp measure --pose Q1 Q2 ... --out DIR/<pose> at each pose"}});
  if (!cfg.pose_schedule)
    throw config::ConfigError(
        {config::Problem{cfg.source,
                         {},
                         "pose_schedule.model",
                         "is missing: --poses needs the robot model whose joints the poses name"}});
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  return config::parse_pose_list(config::detail::read_config_text(poses_file), poses_file, model);
}

std::string pose_dir_name(const std::string& pose_name) {
  std::string s;
  for (char c : pose_name) s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return s.empty() ? "pose" : s;
}

namespace {

void write_index(const std::string& out_dir, const nlohmann::json& index) {
  const fs::path path = fs::path(out_dir) / "poses.json";
  std::ofstream f(path);
  f << index.dump(2) << '\n';
  if (!f) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

std::vector<PoseMeasurement> measure_poses(const std::string& config_path,
                                           const std::vector<config::RobotPoseConfig>& poses,
                                           const std::string& out_dir, const MeasureOptions& o,
                                           const std::function<void(const PoseMeasurement&)>& each) {
  std::vector<PoseMeasurement> done;
  nlohmann::json index = {{"format", "robodamp-pose-measurements"},
                          {"format_version", 1},
                          {"config_source", fs::absolute(config_path).lexically_normal().string()},
                          {"poses", nlohmann::json::array()}};
  fs::create_directories(out_dir);
  for (const auto& p : poses) {
    PoseMeasurement m{
        p.name, p.joints_deg, fs::absolute(fs::path(out_dir) / pose_dir_name(p.name)).lexically_normal().string(), {}};
    spdlog::info("robodamp measure: pose '{}' {} into {}", p.name, config::describe_pose(p.joints_deg), m.dir);
    MeasureOptions at = o;
    at.pose_deg = p.joints_deg;
    at.pose_name = p.name;
    m.outcome = measure(config_path, m.dir, at);
    index["poses"].push_back({{"name", m.name},
                              {"joints_deg", m.joints_deg},
                              {"dir", fs::path(m.dir).filename().string()},
                              {"status", exit_code(m.outcome.status)},
                              {"message", m.outcome.message}});
    write_index(out_dir, index);  // after each pose: an interrupted sequence keeps what it measured
    done.push_back(m);
    if (each) each(done.back());
    if (m.outcome.status != MeasureStatus::kOk) break;
  }
  return done;
}

}  // namespace robodamp::commission
