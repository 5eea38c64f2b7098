// `robodamp measure`: the commissioning measurement (commission/measurement.hpp, docs/identification.md).
// `robodamp identify all --in DIR` turns the directory into a configuration.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "commission/measurement.hpp"

namespace robodamp::apps {

namespace {

struct MeasureArgs {
  std::string config_path{ROBODAMP_DEFAULT_CONFIG};
  std::string out_dir;
  std::string clock;
};

int measure(const MeasureArgs& a) {
  const commission::MeasureOutcome r = commission::measure(a.config_path, a.out_dir, {a.clock});
  if (r.status == commission::MeasureStatus::kConfigError || r.status == commission::MeasureStatus::kFailed ||
      (r.status == commission::MeasureStatus::kWriteError && r.final_state.empty())) {
    std::cerr << "robodamp measure: " << r.message << '\n';
    return commission::exit_code(r.status);
  }
  if (r.manifest.backend == "simulated plant")
    std::cout << "robodamp measure: " << r.impact_records << " of " << r.impact_records_planned
              << " impact records; wrote " << r.frf_files << " FRFs to " << a.out_dir << '\n';
  else
    std::cout << "robodamp measure: the plant side (robodamp plant --measure-out " << a.out_dir
              << ") writes the impact FRFs when the run ends\n";
  std::printf("robodamp measure: state %s, trip %s, chirp played with the loop active over %.1f %% of its ticks, "
              "%llu saturated ticks, peak command %.3f V, %llu frames recorded\n",
              r.final_state.c_str(), r.trip.c_str(), 100.0 * r.chirp_active_share, r.saturated_ticks, r.peak_command_v,
              r.recorded_frames);
  if (r.status != commission::MeasureStatus::kOk) std::cerr << "robodamp measure: " << r.message << '\n';
  return commission::exit_code(r.status);
}

}  // namespace

void register_measure(Registry& r) {
  auto a = std::make_shared<MeasureArgs>();
  CLI::App* sub = r.add("measure",
                        "Commissioning measurement: control off, amplifier on, a chirp on the actuator and hammer impacts "
                        "at every location, recorded for `identify all`",
                        [a] { return measure(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for the recording, the FRFs and measurement.json")->required();
  sub->add_option("--clock", a->clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
}

}  // namespace robodamp::apps
