// `robodamp cut --critical --hil CELL`: the critical depth at a speed through the HIL emulator beside the
// in-process one (emulated_cell.hpp), as the cut's report holds it.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "milling/cut_job.hpp"

namespace robodamp::commission {

// The cell's own controller with `damped`, control off (K = 0, the actuator passive) without; bisected from the
// in-process depth to 1 % (each step a pair of processes). Its line on stdout, progress on stderr; the report's
// "hil" entry.
[[nodiscard]] nlohmann::json hil_critical_json(const std::string& cell_path, const std::string& job_path, bool damped,
                                               const milling::CutJob& job, double rpm, double in_process_mm);

}  // namespace robodamp::commission
