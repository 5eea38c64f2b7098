// What `robodamp identify modes` reports of one FRF (docs/identification.md): where the FRF comes from (a
// universal file's record, a table, or time series through Welch), the fitted modes as a table, JSON and a
// `modes:` list to paste into a preset or a milling job, and the fit's plots; and `identify actuator`'s Eq. 3
// from a table of command and transmitted force, its report and plot. Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "identify/actuator_fit.hpp"
#include "identify/modal_fit.hpp"

namespace robodamp::identify {

// The FRF's files and how to read them (identify modes' options).
struct FrfSource {
  std::string frf_path;     // an FRF: a universal file (58/58b) or a table
  std::string series_path;  // or time series: a table time_s,force_n,response or a universal file's histories
  std::optional<int> record;
  std::string response{"acceleration"};  // --series' response kind, or a universal file's record NODE:DIR
  std::string reference;                 // a universal file's reference NODE:DIR
  std::string kind{"receptance"};        // a table's FRF kind
  double segment_s{10.0}, overlap{0.5};  // Welch
  std::vector<double> band_hz;           // the fit's band (the series' transform up to 1.2 x its top)
};

struct FrfRead {
  FrfData data;
  std::string note;  // what was read from a universal file (its record and units), empty otherwise
};

// "receptance", "mobility" or "accelerance" (anything else: receptance, as the options' checks allow only these).
[[nodiscard]] FrfKind frf_kind_named(const std::string& kind);

// The FRF the source names. Throws std::invalid_argument naming the option and what is allowed.
[[nodiscard]] FrfRead read_frf_source(const FrfSource& s);

struct ModalFitReport {
  nlohmann::json json;
  std::string text;  // the summary line and one line per mode
  std::string yaml;  // the modes: list, headed by where it came from
};

[[nodiscard]] ModalFitReport modal_fit_report(const ModalFit& fit, const std::string& source);

// Measured against fitted magnitude and phase (<prefix>_fit.png, its data in <prefix>_fit.dat) and the
// stabilisation diagram (<prefix>_stabilisation.png) in dir; an empty string, or what went wrong.
[[nodiscard]] std::string plot_modal_fit(const FrfData& d, const ModalFit& fit, const std::string& dir,
                                         const std::string& prefix);

// Eq. 3 from a table time_s,command_v,force_n (the amplifier's command and the force transmitted) through Welch
// (segment_s, overlap), fitted where the coherence is at least min_coherence, in band_hz (empty: the chirp's).
// Throws std::invalid_argument naming the option.
[[nodiscard]] ActuatorFit actuator_from_force_csv(const std::string& path, double segment_s, double overlap,
                                                  const std::vector<double>& band_hz, double min_coherence);

struct ActuatorReport {
  nlohmann::json json;
  std::string text;
};
[[nodiscard]] ActuatorReport actuator_report(const ActuatorFit& fit, const std::string& mounting, double min_coherence);

// Measured against fitted force per volt (magnitude and phase) in dir/name; an empty string, or what went wrong.
[[nodiscard]] std::string plot_actuator_fit(const ActuatorFit& fit, const std::string& dir, const std::string& name);

}  // namespace robodamp::identify
