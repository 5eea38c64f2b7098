// A milling job for the chatter and surface-location-error analyses (docs/physics.md §2-3): tool,
// material, cut, the structure's FRFs seen at the tool tip, and the settings of the lobe and SLE
// computations. YAML with units in the key names, validated like the controller configuration (every
// problem with file, line, key, value, unit and allowed range). Off the real-time path.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace robodamp::config {

enum class ToolKind { kEndMill, kBallEnd };
enum class MillingMode { kDown, kUp };
enum class Axis { kX, kY };

[[nodiscard]] const char* to_string(ToolKind kind);
[[nodiscard]] const char* to_string(MillingMode mode);
[[nodiscard]] const char* to_string(Axis axis);

struct ToolConfig {
  ToolKind kind{ToolKind::kEndMill};
  double diameter_mm{12.7};
  int teeth{3};
  double helix_deg{30.0};
  double flute_length_mm{100.0};  // the cutting length: the deepest axial cut the tool can take
};

// Mechanistic force model (docs/physics.md §2): Ft = kt b h + kte b, Fr = kr b h + kre b. The radial
// coefficient is called kn (normal) in the robot SLE study and Krc in Tian et al. (2024); both spellings are accepted.
struct MaterialConfig {
  std::string name;
  double kt_n_per_mm2{0.0};
  double kr_n_per_mm2{0.0};
  double kte_n_per_mm{0.0};
  double kre_n_per_mm{0.0};
  std::optional<double> ka_n_per_mm2;  // axial (ball end, Tian et al. (2024)): recorded, unused by the 2D models
  // Exponential force model (time domain only): the cutting terms scale as (h / h_ref)^(-chip_exponent),
  // so kt and kr are the specific coefficients at the reference chip h_ref. 0: linear.
  double chip_exponent{0.0};
  double reference_chip_mm{0.1};
};

struct CutConfig {
  MillingMode mode{MillingMode::kDown};
  double radial_mm{2.0};
  double axial_mm{1.0};
  double feed_per_tooth_mm{0.1};
  Axis feed_axis{Axis::kX};  // the machined wall's normal is the other axis
  double spindle_rpm{10000.0};
};

// The driving-point receptance of one location of a damping configuration (config/presets/*.yaml),
// open loop, or closed loop with that configuration's controller (lobes/sle --damped).
struct ControllerPartConfig {
  std::string config_path;  // resolved against the milling file's directory
  int location{1};
  Axis direction{Axis::kY};
  // In memory only (live stability at a pose, analysis::config_in_plane_at_pose): the same point along the
  // other machine axis (0: none): the part is then the loop's robot in both directions, cross terms included.
  int across_location{0};
};

// The robot's TCP receptance from a robot model at a pose (docs/pose_dynamics.md), in the machine frame.
struct PosePartConfig {
  std::string model_path;  // resolved against the milling file's directory
  std::vector<double> joints_deg;
};

// One contribution to the tool-workpiece relative FRF: modal terms per direction pair (stiffness or
// residue form), a location of a damping configuration, or a robot model at a pose.
struct StructurePartConfig {
  std::string name;
  std::array<std::vector<ModeConfig>, 4> modes;  // xx, xy, yx, yy
  std::optional<ControllerPartConfig> controller;
  std::optional<PosePartConfig> pose;
};

// The relative FRF is the sum of its parts (robot + workpiece).
struct StructureConfig {
  std::string name;
  std::vector<StructurePartConfig> parts;
};

struct LobesConfig {
  double rpm_min{1000.0};
  double rpm_max{20000.0};
  int points{2000};  // speeds of the lobe diagram
  bool log_spacing{false};
  std::optional<double> freq_max_hz;  // chatter-frequency search limit; default 4 x the highest resonance
                                      // and at least 4 x the top tooth-passing frequency
  int points_per_mode{160};           // fine chatter-frequency grid across each mode's resonance
};

struct SleConfig {
  double rpm_min{1000.0};
  double rpm_max{20000.0};
  int points{400};
  int axial_slices{40};
  int harmonics{64};         // of the tooth-passing frequency
  double tolerance_um{2.0};  // compensation stops below this part error
  int max_iterations{30};
  std::vector<Axis> surface_normals{Axis::kY};  // conditions are evaluated for each
};

// Time-domain cut simulation (milling/cut_simulation.hpp) and semi-discretization (milling/sdm.hpp).
struct TimeDomainConfig {
  int steps_per_tooth{0};             // 0: the fewest giving min_steps_per_mode_period (and >= 40)
  int min_steps_per_mode_period{20};  // steps per period of the structure's highest mode
  int revolutions{60};                // simulated, start-up included
  int settle_revolutions{20};         // not used by the statistics (start-up transient)
  int axial_slices{20};
  std::vector<double> runout_um;  // per tooth, radial (empty: none)
  std::vector<double> pitch_deg;  // from each tooth to the next, summing to 360 (empty: even pitch)
  int sdm_steps_per_period{40};   // semi-discretization intervals per tooth period
  int sdm_points{200};            // speeds of `lobes --method sdm` over the lobes range
};

// An SLE test condition (the robot SLE study Table 7) with the measured path offset the published predictions add.
struct ConditionConfig {
  std::string name;
  double rpm{0.0};
  double axial_mm{0.0};
  double radial_mm{0.0};
  double feed_per_tooth_mm{0.0};
  double path_offset_x_mm{0.0};
  double path_offset_y_mm{0.0};
};

struct MillingConfig {
  std::string source;
  ToolConfig tool;
  MaterialConfig material;
  CutConfig cut;
  std::vector<StructureConfig> structures;
  std::string structure;  // the one used unless the command line selects another
  LobesConfig lobes;
  SleConfig sle;
  TimeDomainConfig time_domain;
  std::vector<ConditionConfig> conditions;

  [[nodiscard]] const StructureConfig* find_structure(const std::string& name) const;
  // The job's own structure (`structure`); throws ConfigError when it names none.
  [[nodiscard]] const StructureConfig& selected_structure() const;
};

// Throw ConfigError holding every problem found. base_dir resolves controller config paths.
[[nodiscard]] MillingConfig parse_milling_config(const std::string& yaml_text, const std::string& source_name,
                                                 const std::string& base_dir);
[[nodiscard]] MillingConfig load_milling_config(const std::string& path);

}  // namespace robodamp::config
