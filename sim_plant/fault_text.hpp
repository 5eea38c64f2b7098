// A fault as a person types it on the command line (`robodamp run --fault`): KIND:START_S[:DURATION_S], and
// for actuator_saturated KIND:START_S:DURATION_S[:FORCE_N], the force it still gives after the start.
#pragma once

#include <string>

#include "sim_plant/faults.hpp"

namespace robodamp::sim {

// Reads `text` into `out` (start within 0..run_s). False with the reason in `error`, naming the field, its
// unit and its allowed range, or the kinds a KIND may be.
[[nodiscard]] bool parse_fault(const std::string& text, double run_s, Fault& out, std::string& error);

}  // namespace robodamp::sim
