// robodamp configuration: YAML with units in the key names, parsed and validated off the real-time path
// into plain structs. Every problem names file, line, key, value, unit and allowed range; all problems of
// a file are collected and reported together.
#pragma once

#include <complex>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/can_config.hpp"
#include "config/commissioning_config.hpp"
#include "config/pose_schedule_config.hpp"
#include "config/speed_schedule_config.hpp"
#include "config/spindle_config.hpp"
#include "config/supervisory_config.hpp"
#include "rt_settings/rt_settings.hpp"

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

// Problems found after parsing (chain design, plant consistency) carry only their key: this gives each
// one without a line the line of that key in the document, or of its nearest enclosing key present there
// (line 1 when none is), so every problem reads file:line.
[[nodiscard]] std::vector<Problem> located(std::vector<Problem> problems, const std::string& yaml_text);

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Problem> problems);
  [[nodiscard]] const std::vector<Problem>& problems() const { return problems_; }

 private:
  std::vector<Problem> problems_;
};

// The real-time core's own settings (rt_settings/rt_settings.hpp), which this library fills from the file.
using ClockKind = rt::ClockKind;
using rt::to_string;

struct LoopConfig {
  double rate_hz{5000.0};
  // wall: clock_nanosleep on CLOCK_MONOTONIC (hardware, real-time simulation); virtual: ticks back to
  // back as fast as possible, time = tick / rate (bench runs, bit-identical run to run).
  ClockKind clock{ClockKind::kWall};
};

using RealtimeConfig = rt::RealtimeSettings;      // realtime.*
using RecoveryConfig = rt::RecoverySettings;      // supervision.recovery.*
using DerateConfig = rt::DerateSettings;          // supervision.derate.*
using SupervisionConfig = rt::SupervisionLimits;  // supervision.*

struct TelemetryConfig {
  int ring_frames{65536};  // lock-free ring between the loop and the drain thread (power of two)
};

enum class Mounting { kHorizontal, kVertical };

// Sahu et al. (2024) Table 2, Eq. 3.
struct ActuatorConfig {
  Mounting mounting{Mounting::kHorizontal};
  double constant_n_per_v{4.8};
  double natural_freq_hz{9.0};
  double damping_ratio{0.15};
  double delay_s{0.0006};
  double force_limit_n{36.0};
  int location{2};  // structural location (robot.locations id) the actuator pushes on
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
  std::optional<HarmonicNotchConfig> harmonic_notch;  // spindle-locked notches after the chain
  std::optional<SpeedScheduleConfig> speed_schedule;  // controller and K by spindle speed
};

enum class ModeForm { kResidue, kStiffness };

// One mode of an FRF path: Eq. 1 residue form (sigma = re + j im), or modal-stiffness form
// H = 1 / (k (1 - (w/wn)^2 + 2 j zeta w/wn)).
struct ModeConfig {
  ModeForm form{ModeForm::kResidue};
  double natural_freq_hz{0.0};
  double damping_ratio{0.0};
  double residue_re_m_per_n{0.0};
  double residue_im_m_per_n{0.0};
  double stiffness_n_per_m{0.0};
};

// A mode in modal-stiffness form.
[[nodiscard]] inline ModeConfig stiffness_mode(double natural_freq_hz, double damping_ratio, double stiffness_n_per_m) {
  return {ModeForm::kStiffness, natural_freq_hz, damping_ratio, 0.0, 0.0, stiffness_n_per_m};
}

// A structural degree of freedom (a point and a direction). axis_sign is the sign of the tabulated
// FRFs' response axis at this location relative to the common frame: the physical FRF is
// axis_sign(response) * tabulated (docs/physics.md §1: Table 1's location-2 axis is reversed, -1).
struct LocationConfig {
  int id{1};
  std::string name;
  int axis_sign{1};
};

struct FrfConfig {
  std::string name;
  int response_location{1};
  int excitation_location{1};
  std::vector<ModeConfig> modes;
};

struct RobotConfig {
  std::vector<LocationConfig> locations;  // every id used by an FRF, the actuator and the sensor
  std::vector<FrfConfig> frfs;
};

// The control accelerometer (IEPE, e.g. PCB 356B08) and its ADC channel.
struct SensorConfig {
  int location{2};
  double sensitivity_mv_per_g{10.0};
  double range_g{500.0};                  // the sensor clips beyond this
  double noise_density_ug_per_rthz{3.0};  // broadband, white
  double highpass_hz{1.6};                // IEPE coupling, first order: within 5 % above 5 Hz
  int adc_bits{24};
  double adc_range_v{30.0};  // +- full scale
};

// The simulated plant's numerical settings.
struct PlantConfig {
  int oversampling{1};  // internal steps per loop period
  // The amplifier's leads as the simulated robot is wired: 1 as configured, -1 swapped (the actuator pushes
  // the other way from the command: a fault the supervisor must trip on, docs/realtime_loop.md).
  int actuator_wiring{1};
};

// Disturbances present in bench runs.
struct DisturbanceConfig {
  bool drives_on{true};  // the robot's inherent vibration is present with the drives on
  double drive_vibration_hz{3.0};
  double drive_vibration_mps2{0.05};  // amplitude of acceleration at the sensor location, control off
  int drive_vibration_location{1};    // where the equivalent force acts
  std::uint64_t seed{1};
};

// Frequency band where FRF peaks are sought, by the analysis and the bench alike.
struct AnalysisConfig {
  double band_min_hz{4.0};
  double band_max_hz{100.0};
};

// The bench run: averaged impact tests control off and on, and a gain sweep.
struct BenchConfig {
  double impact_peak_n{1000.0};    // small enough not to saturate the actuator
  double impact_duration_ms{1.0};  // half-sine
  double saturating_impact_peak_n{8000.0};
  double saturating_impact_duration_ms{5.0};  // soft tip: more impulse at the robot modes
  int averages{6};
  double record_s{10.0};                 // per impact: frequency resolution 1 / record_s
  int zero_pad{8};                       // evaluation grid = resolution / zero_pad (records decay fully)
  double measurement_highpass_hz{0.16};  // measurement accelerometers (modal grade)
  std::vector<double> sweep_gain_factors{0.5, 0.9, 1.1, 1.5};  // x the predicted maximum stable K
  double sweep_duration_s{20.0};
};

struct Config {
  std::string source;
  std::string yaml_text;  // the text it was parsed from (recordings carry it)
  LoopConfig loop;
  RealtimeConfig realtime;
  SupervisionConfig supervision;
  TelemetryConfig telemetry;
  ActuatorConfig actuator;
  AmplifierConfig amplifier;
  ControllerConfig controller;
  RobotConfig robot;
  SensorConfig sensor;
  PlantConfig plant;
  DisturbanceConfig disturbances;
  AnalysisConfig analysis;
  BenchConfig bench;
  std::optional<CanConfig> can;        // hardware: the CAN link (drivers/can_*); absent for the simulated plant
  std::optional<ModbusConfig> modbus;  // hardware: amplifier and robot registers
  std::vector<ParameterSetRef> parameter_sets;      // other mountings' configurations, selected by the robot
  std::optional<DdsConfig> dds;                     // telemetry and supervised parameters over Fast DDS
  CellConfig cell;                                  // the cell's name on the network (cell.name)
  HilConfig hil;                                    // read by the plant emulator (robodamp plant)
  CommissioningConfig commissioning;                // robodamp measure and the plant side of it
  SpindleConfig spindle;                            // tooth count and speed range (the harmonic notches)
  std::optional<PoseScheduleConfig> pose_schedule;  // parameter sets by pose region (analysis/pose_schedule)
};

// A parameter request's gain against what the supervisor allows (the analysed maximum stable K x
// supervision.max_gain_fraction), worded as the configuration words a problem; nothing when allowed.
[[nodiscard]] std::optional<std::string> gain_request_problem(double gain_ns_per_m, double max_ns_per_m,
                                                              const std::string& why);

// Throw ConfigError holding every problem found.
[[nodiscard]] Config parse_config(const std::string& yaml_text, const std::string& source_name);
[[nodiscard]] Config load_config_file(const std::string& path);

[[nodiscard]] const LocationConfig* find_location(const RobotConfig& robot, int id);

// The supervisor's settings for a configuration (its supervision limits, the loop's rate, the sensor's
// range, the gain ramp, the amplifier's voltage limit), given what the analysis found.
[[nodiscard]] rt::SupervisorSettings supervisor_settings(const Config& cfg, bool analysis_stable,
                                                         double max_stable_gain_ns_per_m, double delay_margin_s = 0.0);

}  // namespace robodamp::config
