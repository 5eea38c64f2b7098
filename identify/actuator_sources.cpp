#include "identify/actuator_sources.hpp"

#include <stdexcept>

#include "identify/commissioning.hpp"
#include "identify/modal_fit.hpp"
#include "identify/modal_fit_report.hpp"

namespace robodamp::identify {

IdentifiedActuator identify_actuator_from(const ActuatorSources& s, double min_coherence) {
  if (!s.band_hz.empty() && (s.band_hz.size() != 2 || !(s.band_hz[1] > s.band_hz[0])))
    throw std::invalid_argument("--band-hz: two frequencies, LO < HI");
  if (s.recording_path.empty() == s.force_csv_path.empty())
    throw std::invalid_argument(
        "give either --recording (a robodamp measure recording, with --structure) or --csv "
        "(time_s,command_v,force_n)");
  IdentifiedActuator out;
  if (s.recording_path.empty()) {
    out.fit = actuator_from_force_csv(s.force_csv_path, s.segment_s, s.overlap, s.band_hz, min_coherence);
    return out;
  }
  if (s.structure_path.empty())
    throw std::invalid_argument(
        "--recording needs --structure: the FRF at the sensor for a force at the actuator "
        "(frf_<sensor>_<actuator>.csv of the same measurement)");
  const ChirpMeasurement m = read_chirp_measurement(s.recording_path);
  out.mounting = config::to_string(m.config.actuator.mounting);
  ModalFitSettings ms;
  ms.band_lo_hz = m.config.analysis.band_min_hz, ms.band_hi_hz = m.config.analysis.band_max_hz;
  ms.max_order = s.max_order.value_or(40);
  const ModalFit structure = fit_modes(read_frf_csv(s.structure_path, frf_kind_named(s.structure_kind)), ms);
  const double lo = s.band_hz.size() == 2 ? s.band_hz[0] : 0.0, hi = s.band_hz.size() == 2 ? s.band_hz[1] : 0.0;
  out.fit = identify_actuator(m, with_collocated_structure(m.config, structure), lo, hi, min_coherence);
  return out;
}

}  // namespace robodamp::identify
