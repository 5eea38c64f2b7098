// robodamp configuration: YAML with units in the key names, parsed and validated off the real-time path
// into plain structs. Every problem names file, line, key, value, unit and allowed range; all problems of
// a file are collected and reported together.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace robodamp::config {

struct SourceMark {
  int line{0};  // 1-based; 0 = unknown
  int column{0};
};

struct Problem {
  std::string file;
  SourceMark mark;
  std::string key;  // dotted path, e.g. controller.chain[3].cutoff_hz
  std::string message;
  [[nodiscard]] std::string to_string() const;  // "file:line:col: key: message"
};

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Problem> problems);
  [[nodiscard]] const std::vector<Problem>& problems() const { return problems_; }

 private:
  std::vector<Problem> problems_;
};

struct LoopConfig {
  double rate_hz{5000.0};
};

enum class Mounting { kHorizontal, kVertical };

// data/seed001_actuator.csv, Eq. 3.
struct ActuatorConfig {
  Mounting mounting{Mounting::kHorizontal};
  double constant_n_per_v{4.8};
  double natural_freq_hz{9.0};
  double damping_ratio{0.15};
  double delay_s{0.0006};
  double force_limit_n{36.0};
};

struct AmplifierConfig {
  double voltage_limit_v{10.0};
  double slew_rate_v_per_s{10000.0};
};

enum class BlockKind { kLowpass2, kHighpass2, kNotch, kIntegrator, kCompensator };
enum class CompensatorModel { kC1, kC2, kC3, kRational };

[[nodiscard]] const char* to_string(BlockKind kind);  // the YAML/JSON name: lowpass2, highpass2, ...
[[nodiscard]] std::optional<BlockKind> block_kind_from(const std::string& name);
[[nodiscard]] const char* to_string(CompensatorModel model);
[[nodiscard]] const char* to_string(Mounting mounting);

struct BlockConfig {
  BlockKind kind{BlockKind::kLowpass2};
  std::string name;  // unique in the chain; defaults to kind with an index
  std::string key;   // where it came from, e.g. controller.chain[2]
  SourceMark mark;
  double cutoff_hz{0.0};      // lowpass2, highpass2
  double damping_ratio{0.0};  // lowpass2, highpass2
  double center_hz{0.0};      // notch
  double bandwidth_hz{0.0};   // notch (a of Eq. 14)
  double leak_hz{0.0};        // integrator (only without a high-pass)
  CompensatorModel model{CompensatorModel::kC2};
  double corner_hz{0.5};             // c1: w_c / 2 pi
  double corner_damping_ratio{1.0};  // c1: z_c (1 reproduces the published phase)
  std::vector<double> numerator;     // rational: coefficients, highest power of s first
  std::vector<double> denominator;
  std::optional<double> prewarp_hz;  // bilinear match frequency; default per block kind
};

struct ControllerConfig {
  double gain_ns_per_m{2000.0};
  double gain_ramp_s{0.5};
  int polarity{1};
  std::optional<double> match_freq_hz;  // compensators' pre-warp; default the dominant robot mode
  std::vector<BlockConfig> chain;
};

// Eq. 1, residue form.
struct ModeConfig {
  double natural_freq_hz{0.0};
  double damping_ratio{0.0};
  double residue_re_m_per_n{0.0};
  double residue_im_m_per_n{0.0};
};

struct FrfConfig {
  std::string name;
  int response_location{1};
  int excitation_location{1};
  std::vector<ModeConfig> modes;
};

struct RobotConfig {
  std::vector<FrfConfig> frfs;
};

struct Config {
  std::string source;
  LoopConfig loop;
  ActuatorConfig actuator;
  AmplifierConfig amplifier;
  ControllerConfig controller;
  RobotConfig robot;
};

// Throw ConfigError holding every problem found.
[[nodiscard]] Config parse_config(const std::string& yaml_text, const std::string& source_name);
[[nodiscard]] Config load_config_file(const std::string& path);

// Frequency of the robot mode with the largest receptance peak, preferring a driving-point FRF at the
// actuator location (2) where the loop closes; nullopt without modal data.
[[nodiscard]] std::optional<double> dominant_mode_hz(const RobotConfig& robot);

}  // namespace robodamp::config
