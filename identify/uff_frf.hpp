// FRFs from universal files (measfiles/uff.hpp, docs/measurement_files.md): a dataset 58 FRF record as
// robodamp's receptance in m/N, its kind (receptance, mobility, accelerance) and units read from the
// record's header and converted, its coherence from the coherence record of the same DOFs; and the
// record a user means, chosen by its number or by its response and reference DOFs. Off the real-time path.
#pragma once

#include <optional>
#include <string>

#include "identify/modal_fit.hpp"
#include "identify/numeric_csv.hpp"
#include "measfiles/uff.hpp"

namespace robodamp::identify {

// A node and a direction: 1..3 = +X..+Z, negative for -X..-Z, 0 = any direction (only as a selection).
struct Dof {
  int node{0};
  int direction{0};
};
// "12:+Y", "12:-z", "12:2", "12" (any direction). Throws std::invalid_argument naming the text.
[[nodiscard]] Dof parse_dof(const std::string& text);
[[nodiscard]] std::string dof_text(int node, int direction);

struct UffSelection {
  std::optional<int> record;  // the Nth function record of the file (1-based)
  std::optional<Dof> response, reference;
  bool to_receptance{true};  // false: the ordinate as measured, in SI (m, m/s or m/s^2 per N or V)
};

// What an FRF record's ordinate and denominator are, in SI.
struct FrfUnits {
  FrfKind kind{FrfKind::kReceptance};
  double to_si{1.0};           // multiply the ordinate by it for m/N, m/s/N or m/s^2/N
  bool per_volt{false};        // the denominator is a voltage (an actuator's FRF), not a force
  bool force_per_volt{false};  // an actuator's force per volt (N/V): the ordinate is a force
  std::string shown;           // "accelerance, g/lbf read as (m/s^2)/N"
};
// Throws std::invalid_argument naming the record and the unit it does not know.
[[nodiscard]] FrfUnits frf_units(const measfiles::UffFunction& f, int record);

// One line per function record: its number, type, DOFs, units and abscissa.
[[nodiscard]] std::string describe_functions(const measfiles::UffFile& file);

struct UffFrf {
  FrfData data;   // receptance m/N (or per volt for an actuator record), coherence when the file has it
  int record{0};  // the function record's number
  const measfiles::UffFunction* function{nullptr};
  FrfUnits units;
};

// The FRF record selected (the file's only FRF when nothing is selected). Throws std::invalid_argument
// naming the file and listing its records when the selection matches none or several.
[[nodiscard]] UffFrf frf_from_uff(const measfiles::UffFile& file, const std::string& name, const UffSelection& s);

// A hammer test's time histories (dataset 58, function type 1): the force record (its ordinate a force)
// and the response record (a displacement, velocity or acceleration; chosen by s.response when the file
// holds several), in SI, on one even time axis. kind: what the response is. Throws std::invalid_argument
// naming the file and listing its records.
struct UffSeries {
  TimeSeries series;
  FrfKind kind{FrfKind::kAccelerance};
  int force_record{0}, response_record{0};
};
[[nodiscard]] UffSeries time_series_from_uff(const measfiles::UffFile& file, const std::string& name,
                                             const UffSelection& s);

// Whether a file is a universal file (its first non-blank line holds -1).
[[nodiscard]] bool looks_like_uff(const std::string& path);

}  // namespace robodamp::identify
