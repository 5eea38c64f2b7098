// Checked reading of YAML maps: every key consumed, every value range-checked with its unit, every
// problem collected with its source position. Internal to the config library.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/config.hpp"
#include "config/number_range.hpp"
#include "config/robot_model_config.hpp"

namespace robodamp::config::detail {

class Diagnostics {
 public:
  explicit Diagnostics(std::string file) : file_(std::move(file)) {}
  void add(const YAML::Mark& mark, std::string key, std::string message);
  void add(SourceMark mark, std::string key, std::string message);
  [[nodiscard]] const std::vector<Problem>& problems() const { return problems_; }
  [[nodiscard]] const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::vector<Problem> problems_;
};

using config::describe_range;
using config::format_number;
using config::in_range;
using config::Range;
using config::range_problem;

[[nodiscard]] SourceMark to_mark(const YAML::Mark& m);

class MapReader {
 public:
  // node must be a map. An absent or wrongly shaped node has been reported once (by the parent or
  // here): reading from it then reports nothing more and gives the defaults.
  MapReader(Diagnostics& d, const YAML::Node& node, std::string path, const YAML::Mark& parent_mark);

  [[nodiscard]] std::optional<double> number(const std::string& key, const Range& range,
                                             std::optional<double> default_value = std::nullopt);
  [[nodiscard]] std::optional<std::string> choice(const std::string& key, const std::vector<std::string>& allowed,
                                                  std::optional<std::string> default_value = std::nullopt);
  // Any non-empty string.
  [[nodiscard]] std::optional<std::string> text(const std::string& key, std::optional<std::string> default_value);
  [[nodiscard]] std::optional<std::vector<double>> number_list(const std::string& key, std::string_view unit);
  // The raw child (an undefined node if absent), for nested maps and sequences.
  [[nodiscard]] YAML::Node child(const std::string& key, bool required, std::string_view what);
  // Reports keys that were never asked for, and duplicates.
  void finish();

  [[nodiscard]] std::string path_of(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  [[nodiscard]] YAML::Mark mark() const { return mark_; }
  [[nodiscard]] Diagnostics& diagnostics() { return d_; }

 private:
  YAML::Node lookup(const std::string& key);
  Diagnostics& d_;
  YAML::Node node_;
  std::string path_;
  YAML::Mark mark_;
  std::vector<std::string> known_;
  bool quiet_{false};
};

// The whole file; ConfigError naming it if it cannot be read.
[[nodiscard]] std::string read_config_text(const std::string& path);
// The top-level map of a document; ConfigError (syntax error, or not a map: expected names the keys).
[[nodiscard]] YAML::Node load_top_map(Diagnostics& d, const std::string& yaml_text, const std::string& expected);
// True for a key that is given and not null.
[[nodiscard]] bool present(const YAML::Node& n);
// A whole number in range.
[[nodiscard]] std::optional<int> read_int(MapReader& r, const std::string& key, const Range& range,
                                          std::optional<double> def = {});
// +1 or -1.
[[nodiscard]] std::optional<int> read_sign(MapReader& r, const std::string& key, int def);
[[nodiscard]] std::optional<bool> read_bool(MapReader& r, const std::string& key, bool def);
// The optional modbus, parameter_sets, dds and hil sections (config/supervisory_config.hpp).
void read_supervisory(MapReader& top, Config& c);
// The dds section alone (the dashboard's file has one too).
[[nodiscard]] std::optional<DdsConfig> read_dds_section(MapReader& top);
// The controller's optional harmonic_notch map and the optional spindle section (config/spindle_config.hpp).
[[nodiscard]] std::optional<HarmonicNotchConfig> read_harmonic_notch(MapReader& controller,
                                                                     std::optional<double> rate_hz);
[[nodiscard]] SpindleConfig read_spindle(MapReader& top, const std::string& source);
[[nodiscard]] std::optional<SpeedScheduleConfig> read_speed_schedule(MapReader& controller,
                                                                     std::optional<double> rate_hz);
// One block of controller.chain (or a block that replaces one), checked like the chain's.
[[nodiscard]] std::optional<BlockConfig> read_chain_block(Diagnostics& d, const YAML::Node& node,
                                                          const std::string& key, std::optional<double> rate_hz);
// The optional pose_schedule section (config/pose_schedule_config.hpp); the robot model it names is loaded.
[[nodiscard]] std::optional<PoseScheduleConfig> read_pose_schedule(MapReader& top, const std::string& source);
// The optional commissioning section (config/commissioning_config.hpp).
[[nodiscard]] CommissioningConfig read_commissioning(MapReader& top);
// One mode in residue (Eq. 1) or modal-stiffness form; natural_freq_hz checked against frequency_range.
[[nodiscard]] ModeConfig read_mode(MapReader& mr, const Range& frequency_range);

// A key naming a robot model file: found (the configuration's folder, then the data folders: file_paths.hpp)
// and read; what is wrong with it is reported at the key (key: its full name). written and resolved are set.
[[nodiscard]] std::optional<RobotModelConfig> read_robot_model_file(MapReader& r, const std::string& key,
                                                                    const std::string& source, const std::string& value,
                                                                    std::string& written, std::string& resolved);

}  // namespace robodamp::config::detail
