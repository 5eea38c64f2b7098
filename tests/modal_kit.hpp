// A modal kit's export for the real-cell tests: the FRFs between the locations of a simulated impact test
// (robodamp measure on the simulated plant), every ordinate scaled by `calibration` (the kit's sensitivity
// error), written as a binary universal file without the actuator's record (the kit has no actuator).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "commission/measurement.hpp"
#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"

namespace robodamp::test {

// robot: the configuration measured; measure_dir: where the measurement goes; returns uff_path.
inline std::string modal_kit_export(const std::string& robot, const std::string& measure_dir,
                                    const std::string& uff_path, double calibration) {
  const commission::MeasureOutcome m = commission::measure(robot, measure_dir);
  EXPECT_EQ(m.status, commission::MeasureStatus::kOk) << m.message;
  measfiles::UffFile f = measfiles::read_uff(measure_dir + "/" + identify::kMeasurementUffName);
  std::vector<measfiles::UffFunction> kept;
  for (auto& fn : f.functions) {
    if (fn.reference_entity == identify::kVoltageEntity) continue;
    if (fn.function_type == measfiles::kUffFrf)
      for (auto& y : fn.y) y *= calibration;
    kept.push_back(fn);
  }
  f.functions = kept;
  measfiles::write_uff(uff_path, f, measfiles::UffEncoding::kBinary);
  return uff_path;
}

}  // namespace robodamp::test
