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
  if (!cfg.pose_schedule)
    throw config::ConfigError({config::Problem{cfg.source, {}, "pose_schedule.model",
                                               "is missing: --poses needs the robot model whose joints the poses name"}});
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  return config::parse_pose_list(config::detail::read_config_text(poses_file), poses_file, model);
}

std::string pose_dir_name(const std::string& pose_name) {
  std::string s;
  for (char c : pose_name) s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return s.empty() ? "pose" : s;
}

std::vector<PoseMeasurement> measure_poses(const std::string& config_path,
                                           const std::vector<config::RobotPoseConfig>& poses, const std::string& out_dir,
                                           const MeasureOptions& o, const std::function<void(const PoseMeasurement&)>& each) {
  std::vector<PoseMeasurement> done;
  nlohmann::json index = {{"format", "robodamp-pose-measurements"}, {"format_version", 1},
                          {"config_source", fs::absolute(config_path).lexically_normal().string()},
                          {"poses", nlohmann::json::array()}};
  fs::create_directories(out_dir);
  for (const auto& p : poses) {
    PoseMeasurement m{p.name, p.joints_deg, fs::absolute(fs::path(out_dir) / pose_dir_name(p.name)).lexically_normal().string(), {}};
    spdlog::info("robodamp measure: pose '{}' {} into {}", p.name, config::describe_pose(p.joints_deg), m.dir);
    MeasureOptions at = o;
    at.pose_deg = p.joints_deg;
    at.pose_name = p.name;
    m.outcome = measure(config_path, m.dir, at);
    index["poses"].push_back({{"name", m.name}, {"joints_deg", m.joints_deg}, {"dir", fs::path(m.dir).filename().string()},
                              {"status", exit_code(m.outcome.status)}, {"message", m.outcome.message}});
    done.push_back(m);
    if (each) each(done.back());
    if (m.outcome.status != MeasureStatus::kOk) break;
  }
  std::ofstream f(fs::path(out_dir) / "poses.json");
  f << index.dump(2) << '\n';
  if (!f) throw std::runtime_error("cannot write " + (fs::path(out_dir) / "poses.json").string());
  return done;
}

}  // namespace robodamp::commission
