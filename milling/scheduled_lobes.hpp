// The damped lobes a speed schedule gives (controller.speed_schedule, docs/tuning.md): at each speed of the
// accurate diagram's grid the sampled loop's semi-discretization with the controller and K of the band that
// holds the speed (K = 0: the open loop's SDM at that speed, where the damper commands nothing), and the open
// loop at the same speeds, so the two compare speed by speed. `robodamp lobes --damped` shows it beside the
// fixed gain's lobes when the job's damping configuration has a schedule. Off the real-time path.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config/milling_config.hpp"
#include "config/config.hpp"
#include "milling/sdm.hpp"
#include "milling/studies.hpp"

namespace robodamp::milling {

struct ScheduledLobes {
  LobeStudy study;              // method "sampled-loop SDM, speed schedule"
  std::vector<double> open_mm;  // the open loop's SDM at each of study.curve's speeds
  std::size_t below_open{0};    // speeds where the schedule's limit is below the open loop's by > 0.5 %
  std::size_t bands{0};
  std::string config;  // the damping configuration whose schedule it is
};

// Each speed's limit with the controller and K of the band of cell's speed schedule that holds it (the
// structure's controller parts running them), open[i] where the band's K is 0.
[[nodiscard]] std::vector<SdmPoint> scheduled_limits(const config::StructureConfig& structure,
                                                     const config::MillingConfig& job, const config::Config& cell,
                                                     const std::vector<double>& speeds,
                                                     const std::vector<SdmPoint>& open);

// Nothing when the structure's (first) controller configuration has no speed schedule. rpms: the direct test's
// speeds (the band holding each). progress(done, of) as the speeds finish.
[[nodiscard]] std::optional<ScheduledLobes> scheduled_lobe_study(
    const config::StructureConfig& structure, const config::MillingConfig& job, const std::vector<double>& rpms,
    const std::function<void(std::size_t done, std::size_t of)>& progress = {});

}  // namespace robodamp::milling
