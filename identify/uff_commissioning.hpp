// robodamp's commissioning measurement and its identified modes as universal files, and identify all from
// such a file (docs/measurement_files.md): a modal package opens what robodamp measured, and robodamp
// commissions from what a modal package exports. Off the real-time path.
//
// The measurement file holds, per pair of locations (node = the configuration's location id, direction
// +Y: robodamp's one machining direction), the impact FRF as receptance (dataset 58, m/N) with its
// coherence, and the actuator chirp's acceleration at the sensor per volt at the amplifier (58, m/s^2
// per V, reference entity "VOLTAGE") with its coherence; the locations as nodes (dataset 15, no
// coordinates: robodamp does not know them). The modes file holds each mode of the actuator's column as
// a complex mode (dataset 55: pole, shape scaled to modal A = 1 so that the residue between nodes g and h
// is psi_g psi_h).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "identify/commissioning.hpp"
#include "identify/uff_frf.hpp"
#include "measfiles/uff.hpp"

namespace robodamp::identify {

inline constexpr const char* kMeasurementUffName = "measurement.uff";
inline constexpr const char* kModesUffName = "modes.uff";
inline constexpr const char* kVoltageEntity = "VOLTAGE";

[[nodiscard]] measfiles::UffFile measurement_to_uff(const CommissioningInputs& in);
[[nodiscard]] measfiles::UffFile modes_to_uff(const CommissioningResult& r);

// The FRF record between two nodes (either way round for a force; the sensor's response to the actuator's
// voltage for a volt); nullopt when the file holds none. Throws std::invalid_argument when it holds two.
[[nodiscard]] std::optional<UffFrf> uff_frf_between(const measfiles::UffFile& file, const std::string& path,
                                                    int response, int reference, bool per_volt);

// identify all's inputs from a universal file and the configuration the measurement ran with: an FRF
// per force between every pair of the configuration's locations (either way round), and the actuator's
// acceleration per volt at the sensor. Throws std::invalid_argument naming the pair or record missing.
[[nodiscard]] CommissioningInputs read_measurement_uff(const std::string& uff_path, const std::string& config_path);

// identify all from the files `robodamp identify all` names: a measure directory (`in_dir`, with the user's tap
// tests from `tap_tests` when it names them, checked against the actuator's chirp and refused when they disagree)
// or a universal file (`uff_path`) with the configuration it was measured with; the identified modes written as a
// universal file when `modes_uff` names one. What it checked and wrote on `out`; throws std::exception with the
// reason.
struct AllFiles {
  std::string in_dir, uff_path, config_path;
  std::vector<std::string> tap_tests;
  std::string modes_uff;
};
[[nodiscard]] CommissioningResult identify_all_files(const AllFiles& f, const CommissioningSettings& s,
                                                     std::ostream& out);

}  // namespace robodamp::identify
