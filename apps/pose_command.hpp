// `robodamp pose`'s arguments, shared by its subcommands' files (apps/pose_command.cpp, pose_fit_command.cpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "apps/pose_tune_command.hpp"
#include "config/config.hpp"
#include "config/file_paths.hpp"
#include "config/robot_model_config.hpp"

namespace robodamp::apps {

struct PoseArgs {
  std::string what;
  std::string model_path{config::shipped_file("robots/planar_three_link.yaml")};
  std::vector<double> joints_deg;
  std::string pose_name;
  JsonOut json;
  std::string json_out_path;  // the deprecated --json-out FILE: the JSON also there
  std::string plot_dir, plot_path;
  int modes{4};
  std::vector<double> band_hz{2.0, 60.0};
  std::vector<int> vary{2, 3};
  int steps{21};
  std::vector<std::string> measured;                // "Q1,Q2,Q3:path"
  std::vector<std::string> measurements, hold_out;  // fit: measure directories; pose names kept out of the fit
  std::string direction{"yy"};
  std::vector<double> fit_band_hz{10.0, 30.0};
  int restarts{3}, particles{40}, iterations{150}, seed{1};
  std::optional<int> fit_modes;  // fit: the model's form (robot::PoseFitSettings::modes)
  std::string out_path;
  std::string csv_path;
  double csv_step_hz{0.1};
  std::string job_path;       // map: a milling job with a pose part: its minimum limiting depth at each pose
  std::string method{"sdm"};  // map: the accurate method, or "zoa" (the zero-order preview)
  PoseTuneArgs tune;          // tune (apps/pose_tune_command.hpp)
  bool model_given{false};
  bool modes_given{false};
};

// The deprecated --json-out FILE: the JSON also there (true when written or not asked for).
bool also_json_out(const PoseArgs& a, const nlohmann::json& j);

// pose fit: the joints' stiffness and damping fitted to measured TCP receptances (robot/pose_fit.hpp).
int run_fit(const config::RobotModelConfig& m, const PoseArgs& a);

}  // namespace robodamp::apps
