// `robodamp identify actuator`: Eq. 3 (T, natural frequency, damping, delay) from a chirp recorded by
// robodamp measure (with the structure's FRF at the sensor) or from a CSV of command and transmitted
// force. `robodamp identify all`: a complete configuration from a robodamp measure directory.
// docs/identification.md.
#include <cstdio>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/identify_command.hpp"
#include "identify/actuator_sources.hpp"
#include "identify/modal_fit_report.hpp"
#include "identify/uff_commissioning.hpp"

namespace robodamp::apps {

namespace {

constexpr double kActuatorMinCoherence = 0.9;

}  // namespace

int run_identify_actuator(const IdentifyArgs& a) {
  identify::IdentifiedActuator id;
  try {
    id = identify::identify_actuator_from(
        {a.recording_path, a.structure_path, a.kind, a.csv_path, a.segment_s, a.overlap, a.band_hz, a.max_order},
        kActuatorMinCoherence);
  } catch (const std::exception& e) {  // the options, a file that cannot be read, a recorded configuration that fails
    std::cerr << "robodamp identify actuator: " << e.what() << '\n';
    return 2;
  }
  const identify::ActuatorReport r = identify::actuator_report(id.fit, id.mounting, kActuatorMinCoherence);
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
    r = identify::identify_all_files({a.in_dir, a.uff_path, a.config_path, a.tap_tests, a.modes_uff_path}, s,
                                     std::cout);
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
