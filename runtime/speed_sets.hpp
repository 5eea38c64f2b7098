// The sets of a speed schedule (config/speed_schedule_config.hpp) as the supervisor holds them: which set
// each band names, and each band's K against its own set's analysed limit. Off the real-time path.
#pragma once

#include <vector>

#include "config/config.hpp"
#include "control/controller_params.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::runtime {

// A configuration's own K schedule names set 0 for "this configuration's controller": in a set added at
// own_index (a mounting's set) those bands name it.
void own_speed_bands(control::ControllerParams& p, std::size_t own_index);

// Every band's K against supervision.max_gain_fraction x the analysed maximum stable K of the set it runs
// (as a gain request would be checked), so every K it ramps to and through is a stable loop. Throws
// config::ConfigError naming the band, located in the set's configuration.
void check_speed_bands(const rt::Supervisor& sup, const std::vector<config::Config>& set_configs);

}  // namespace robodamp::runtime
