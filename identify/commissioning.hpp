// Commissioning from a measurement directory (docs/identification.md, "Commissioning"): what
// robodamp measure wrote (measurement.json, the loop's recording with the actuator chirp, and the
// plant side's impact FRFs frf_<response>_<excitation>.csv) in; the robot's modes per FRF, the
// actuator's Eq. 3 parameters and a complete controller configuration out, with the compensator
// matched at the identified dominant mode and the loop polarity the analysis recommends.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/modal_test.hpp"
#include "config/config.hpp"
#include "identify/actuator_fit.hpp"
#include "identify/modal_fit.hpp"

namespace robodamp::identify {

inline constexpr const char* kManifestName = "measurement.json";
inline constexpr const char* kRecordingName = "loop.rdrec";

struct MeasurementManifest {
  std::string config_source;  // absolute path of the configuration measured with
  std::string config_text;
  std::string backend;
  double loop_rate_hz{0.0};
  analysis::CommissioningPlan plan;
  std::vector<std::pair<int, std::string>> locations;  // id, name
  int sensor_location_id{0}, actuator_location_id{0};
  nlohmann::json run;  // the run's summary (state, trips, saturation)
  // The robot's joint angles during the measurement (robodamp measure --pose; empty: not stated) and the
  // robot model file they refer to (the configuration's pose_schedule.model).
  std::vector<double> pose_deg;
  std::string pose_name, robot_model;
};

[[nodiscard]] nlohmann::json to_json(const MeasurementManifest& m);
// Throws std::invalid_argument naming the file and what is missing.
[[nodiscard]] MeasurementManifest read_manifest(const std::string& dir);

// The actuator chirp of a robodamp measure recording: the acceleration per volt at the sensor, averaged
// over the chirp's periods after the first (the transient), and the configuration it ran with.
struct ChirpMeasurement {
  analysis::FrfEstimate accel_per_volt;
  config::Config config;
  int periods_averaged{0};
  double fs_hz{0.0};
  double f0_hz{0.0}, f1_hz{0.0};
};
// Throws std::invalid_argument (no such file, no test signal, too short) or rt::RecordingError.
// config_source: where the recorded configuration's relative paths resolve from (empty: the recording's
// own record of it). A chirp on command (measure --along-path: one per dwell) starts at the tick after a
// start_excitation command: the one starting at start_s (a dwell's measurement.json plan, within half a
// tick), or the first without it.
[[nodiscard]] ChirpMeasurement read_chirp_measurement(const std::string& recording_path,
                                                      const std::string& config_source = {},
                                                      std::optional<double> start_s = std::nullopt);

// Eq. 3 from the chirp: force per volt through the structure's receptance (sensor per actuator force),
// the configured sensor's coupling and the loop's hold (identify/actuator_fit.hpp), fitted over the
// chirp's band within [band_lo, band_hi] (0, 0: the configuration's analysis band), then refined
// against the exactly sampled plant (identify/actuator_discrete.hpp). structure: a configuration
// holding the identified robot.
[[nodiscard]] ActuatorFit identify_actuator(const ChirpMeasurement& m, const config::Config& structure,
                                            double band_lo_hz, double band_hi_hz, double min_coherence);

// The chirp's configuration with its robot replaced by one identified FRF between the sensor and the
// actuator, which must then share a location (the collocated velocity feedback of the presets).
// Throws std::invalid_argument otherwise.
[[nodiscard]] config::Config with_collocated_structure(const config::Config& base, const ModalFit& fit);

struct IdentifiedFrf {
  std::string name;
  int response_id{0}, excitation_id{0};
  std::string file;
  ModalFit fit;
  FrfData data;
};

struct CommissioningSettings {
  int max_order{60};          // the common-pole fit: a close pair 2 % apart settles from about order 50
  double min_coherence{0.8};  // modal fits
  double actuator_min_coherence{0.9};
};

struct CommissioningResult {
  MeasurementManifest manifest;
  std::vector<IdentifiedFrf> frfs;
  std::string pole_fit;  // "common poles over N FRFs" or "poles per FRF"
  ActuatorFit actuator;
  int actuator_periods{0};  // chirp periods averaged
  double dominant_mode_hz{0.0};
  int polarity{1};
  std::string polarity_reason;
  std::string yaml;       // the identified configuration
  config::Config config;  // it, parsed and validated
  bool stable{false};
  std::optional<double> max_stable_gain_ns_per_m;
  double gain_ns_per_m{0.0};
  std::optional<double> gain_margin_db, phase_margin_deg;
  std::vector<std::pair<std::string, double>> improvements_pct;  // discrete loop, per FRF
};

// The FRF between two locations, either way round. Throws std::invalid_argument naming them when none is.
[[nodiscard]] const IdentifiedFrf& path_between(const std::vector<IdentifiedFrf>& frfs, int a, int b);

// What identify all works from: a robodamp measure directory (read_measurement_dir) or a universal file
// and the configuration measured with (identify/uff_commissioning.hpp).
struct CommissioningInputs {
  MeasurementManifest manifest;
  std::vector<IdentifiedFrf> frfs;  // one per pair of locations, data only
  ChirpMeasurement chirp;
  // The actuator's force per volt measured directly (a modal lab's blocked-force test): fitted as it is,
  // in place of the chirp's acceleration per volt through the identified structure.
  std::optional<ActuatorFrf> force_per_volt;
  std::string identified_path;  // where relative names of the identified configuration resolve from
};
// Throws std::invalid_argument naming what is missing or bad, or rt::RecordingError.
[[nodiscard]] CommissioningInputs read_measurement_dir(const std::string& dir);

// Throws std::invalid_argument (bad or missing measurement, a fit that fails) or config::ConfigError
// (the identified configuration does not validate).
[[nodiscard]] CommissioningResult identify_all(const std::string& dir, const CommissioningSettings& s);
[[nodiscard]] CommissioningResult identify_all(const CommissioningInputs& in, const CommissioningSettings& s);

[[nodiscard]] nlohmann::json to_json(const CommissioningResult& r);
[[nodiscard]] std::string summary_text(const CommissioningResult& r);

}  // namespace robodamp::identify
