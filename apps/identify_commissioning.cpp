// `robodamp identify actuator`: Eq. 3 (T, natural frequency, damping, delay) from a chirp recorded by
// robodamp measure (with the structure's FRF at the sensor) or from a CSV of command and transmitted
// force. `robodamp identify all`: a complete configuration from a robodamp measure directory.
// docs/identification.md.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/gnuplot.hpp"
#include "apps/identify_command.hpp"
#include "identify/actuator_fit.hpp"
#include "identify/commissioning.hpp"
#include "identify/modal_fit_report.hpp"
#include "identify/numeric_csv.hpp"
#include "identify/tap_tests.hpp"
#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"
#include "rt/recording.hpp"

namespace robodamp::apps {

namespace {

constexpr double kActuatorMinCoherence = 0.9;

identify::FrfKind kind_of(const std::string& k) {
  return k == "mobility"      ? identify::FrfKind::kMobility
         : k == "accelerance" ? identify::FrfKind::kAccelerance
                              : identify::FrfKind::kReceptance;
}

}  // namespace

int run_identify_actuator(const IdentifyArgs& a) {
  identify::ActuatorFit fit;
  std::string mounting = "unknown";
  try {
    if (!a.band_hz.empty() && (a.band_hz.size() != 2 || !(a.band_hz[1] > a.band_hz[0])))
      throw std::invalid_argument("--band-hz: two frequencies, LO < HI");
    if (a.recording_path.empty() == a.csv_path.empty())
      throw std::invalid_argument(
          "give either --recording (a robodamp measure recording, with --structure) or --csv "
          "(time_s,command_v,force_n)");
    if (!a.recording_path.empty()) {
      if (a.structure_path.empty())
        throw std::invalid_argument(
            "--recording needs --structure: the FRF at the sensor for a force at the actuator "
            "(frf_<sensor>_<actuator>.csv of the same measurement)");
      const identify::ChirpMeasurement m = identify::read_chirp_measurement(a.recording_path);
      mounting = config::to_string(m.config.actuator.mounting);
      identify::ModalFitSettings ms;
      ms.band_lo_hz = m.config.analysis.band_min_hz, ms.band_hi_hz = m.config.analysis.band_max_hz;
      ms.max_order = a.max_order.value_or(40);
      const identify::ModalFit structure =
          identify::fit_modes(identify::read_frf_csv(a.structure_path, kind_of(a.kind)), ms);
      const double lo = a.band_hz.size() == 2 ? a.band_hz[0] : 0.0, hi = a.band_hz.size() == 2 ? a.band_hz[1] : 0.0;
      fit = identify::identify_actuator(m, identify::with_collocated_structure(m.config, structure), lo, hi,
                                        kActuatorMinCoherence);
    } else {
      fit = identify::actuator_from_force_csv(a.csv_path, a.segment_s, a.overlap, a.band_hz, kActuatorMinCoherence);
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify actuator: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {  // a recording that cannot be read, a configuration in it that does not validate
    std::cerr << "robodamp identify actuator: " << e.what() << '\n';
    return 2;
  }
  const identify::ActuatorReport r = identify::actuator_report(fit, mounting, kActuatorMinCoherence);
  std::fputs(r.text.c_str(), stdout);
  if (a.json.given) {
    if (!emit_json(a.json, r.json.dump(2), "identify")) return 1;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
  }
  return 0;
}

int run_identify_all(const IdentifyArgs& a) {
  if (a.in_dir.empty() == a.uff_path.empty() || a.out_path.empty() || a.uff_path.empty() != a.config_path.empty()) {
    std::cerr
        << "robodamp identify all: --in (a robodamp measure directory) or --uff (a universal file) with --config (the "
           "configuration it was measured with), and --out (the configuration to write) are required\n";
    return 2;
  }
  identify::CommissioningSettings s;
  if (a.max_order) s.max_order = *a.max_order;
  identify::CommissioningResult r;
  try {
    identify::TapTests taps;
    const identify::CommissioningInputs in =
        !a.uff_path.empty()    ? identify::read_measurement_uff(a.uff_path, a.config_path)
        : !a.tap_tests.empty() ? identify::inputs_with_tap_tests(a.in_dir, a.tap_tests, taps)
                               : identify::read_measurement_dir(a.in_dir);
    r = identify::identify_all(in, s);
    if (!a.tap_tests.empty()) {
      const identify::TapTestConsistency c = identify::check_tap_tests(in, r, taps);
      std::printf("robodamp identify all: the tap tests against the actuator's chirp: %s\n", c.summary().c_str());
      if (const std::string f = c.failure(); !f.empty()) throw std::invalid_argument(f);
    }
    if (!a.modes_uff_path.empty()) {
      measfiles::write_uff(a.modes_uff_path, identify::modes_to_uff(r), measfiles::UffEncoding::kAscii);
      std::printf("wrote %s\n", a.modes_uff_path.c_str());
    }
  } catch (const std::exception& e) {
    std::cerr << "robodamp identify all: " << e.what() << '\n';
    return 2;
  }
  std::printf("robodamp identify all: %s (%s, measured with %s)\n",
              (a.uff_path.empty() ? a.in_dir : a.uff_path).c_str(), r.manifest.backend.c_str(),
              r.manifest.config_source.c_str());
  std::cout << identify::summary_text(r);
  {
    std::ofstream out(a.out_path);
    out << r.yaml;
    if (!out) {
      std::cerr << "--out " << a.out_path << ": cannot write\n";
      return 1;
    }
  }
  std::printf("wrote %s\n", a.out_path.c_str());
  if (!a.plot_dir.empty()) {
    std::string e;
    for (const auto& f : r.frfs)
      if (e.empty()) e = identify::plot_modal_fit(f.data, f.fit, a.plot_dir, f.name);
    if (e.empty()) e = identify::plot_actuator_fit(r.actuator, a.plot_dir, "actuator_fit.png");
    if (!e.empty()) {
      std::cerr << "plot: " << e << '\n';
      return 1;
    }
    std::printf("wrote plots in %s\n", a.plot_dir.c_str());
  }
  if (a.json.given) {
    if (!emit_json(a.json, identify::to_json(r).dump(2), "identify")) return 1;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
  }
  if (!r.stable) {
    std::cerr << "robodamp identify all: the identified loop is unstable at the configured gain: lower "
                 "controller.gain_ns_per_m before running it\n";
    return 3;
  }
  return 0;
}

}  // namespace robodamp::apps
