// Where `robodamp identify actuator` reads Eq. 3 from: a robodamp measure recording of the actuator's chirp
// with the structure's FRF at the sensor for a force at the actuator, or a table of the amplifier's command and
// the force it transmitted (docs/identification.md). Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "identify/actuator_fit.hpp"

namespace robodamp::identify {

struct ActuatorSources {
  std::string recording_path;  // a robodamp measure recording (the chirp), with structure_path
  std::string structure_path;  // frf_<sensor>_<actuator>.csv of the same measurement
  std::string structure_kind{"receptance"};
  std::string force_csv_path;            // or time_s,command_v,force_n
  double segment_s{10.0}, overlap{0.5};  // the table's Welch
  std::vector<double> band_hz;           // the fit's band LO HI (empty: the chirp's or the configuration's)
  std::optional<int> max_order;          // the structure's modal fit (default 40)
};

struct IdentifiedActuator {
  ActuatorFit fit;
  std::string mounting{"unknown"};  // the recording's actuator.mounting; a table does not say
};

// Eq. 3 from whichever source is given, fitted where the coherence is at least min_coherence. Throws
// std::invalid_argument naming the option when both or neither source is given, the band is not LO < HI, or a
// recording comes without its structure; what reading the files throws passes through.
[[nodiscard]] IdentifiedActuator identify_actuator_from(const ActuatorSources& s, double min_coherence);

}  // namespace robodamp::identify
