// The parts of the commissioning measurement that measuring along the robot's path shares with it
// (commission/measurement.cpp, commission/path_measurement.cpp).
#pragma once

#include <string>

#include "commission/measurement.hpp"

namespace robodamp::commission::detail {

// The plan of a run with these options: without impacts the run ends a second after the chirp.
[[nodiscard]] analysis::CommissioningPlan plan_for(const config::Config& cfg, const sim::PlantModel& model,
                                                   const MeasureOptions& o);

// The configuration the loop runs: control off (every set's gain 0) unless the chirp verifies the controller.
[[nodiscard]] config::Config running_config(const config::Config& cfg, const MeasureOptions& o);

void fill_manifest(identify::MeasurementManifest& m, const std::string& config_path, const config::Config& cfg,
                   const sim::PlantModel& model, const analysis::CommissioningPlan& plan);

// measurement.json (with the refusal, if any) and measurement.unv: with the impacts measured in process all
// of it; with the chirp alone the actuator's FRF at the sensor with its coherence. A write error sets out.
void write_outputs(MeasureOutcome& out, const std::string& out_dir, bool impacts_here, bool chirp_only);

}  // namespace robodamp::commission::detail
