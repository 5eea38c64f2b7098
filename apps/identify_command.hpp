// `robodamp identify`: its options (apps/identify_command.cpp registers them) and the handlers that
// live in their own files (apps/identify_commissioning.cpp: `identify actuator` and `identify all`;
// apps/identify_ball_end.cpp: `identify cutting --ball-end`).
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include <vector>

#include "identify/modal_fit.hpp"

namespace robodamp::apps {

struct IdentifyArgs {
  std::string what;
  std::string csv_path, yaml_path;
  JsonOut json;
  int teeth{0};
  double diameter_mm{0.0}, axial_mm{0.0}, radial_mm{0.0};
  std::string mode{"down"};
  // cutting from force records
  std::vector<std::string> records;
  std::string tests_path, axes{"fx,fy,fz"}, force_on{"workpiece"};
  std::vector<double> feeds_mm;
  double rpm{0.0};
  // modes
  std::string frf_path, kind{"receptance"}, plot_dir;
  std::string series_path, response{"acceleration"};
  std::optional<int> record;  // a universal file's function record
  std::string reference;      // a universal file's reference DOF
  double segment_s{10.0}, overlap{0.5};
  std::vector<double> band_hz;
  std::optional<int> max_order;  // default: 40 for one FRF, CommissioningSettings{}.max_order for all
  // cutting, ball end (slot milling)
  bool ball_end{false};
  double helix_deg{30.0};
  int order{3};
  // actuator and all
  std::string recording_path, structure_path, in_dir, out_path;
  std::string uff_path, config_path, modes_uff_path;  // all: from a universal file
  std::vector<std::string> tap_tests;                 // all: --in's chirp with the user's tap tests
};

// A fit's report: its text on stdout, its JSON where --json asked and its YAML block to --yaml, each file named
// as written. False when the JSON cannot be written.
[[nodiscard]] bool print_identified(const IdentifyArgs& a, const std::string& text, const nlohmann::json& json,
                                    const std::string& yaml);
[[nodiscard]] int run_identify_actuator(const IdentifyArgs& a);
[[nodiscard]] int run_identify_ball_end(const IdentifyArgs& a);
[[nodiscard]] int run_identify_all(const IdentifyArgs& a);
[[nodiscard]] int run_identify_cutting(const IdentifyArgs& a);

}  // namespace robodamp::apps
