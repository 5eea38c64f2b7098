// The controllers a speed schedule may run and the gains it tries of each (tune/speed_schedule.hpp): the
// largest K with every margin, and gains log-spaced below it. Off the real-time path.
#pragma once

#include <vector>

#include "tune/speed_schedule.hpp"

namespace robodamp::tune {

// cell's own controller first, then each of others in cell's chain; each with its loop model, K_max, top gain
// (and why it stops there) and the gains tried.
[[nodiscard]] std::vector<ScheduleController> schedule_controllers(const config::Config& cell,
                                                                   const std::vector<NamedController>& others,
                                                                   const ScheduleSettings& s);

}  // namespace robodamp::tune
