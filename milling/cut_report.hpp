// What `robodamp cut` reports of one simulated cut (docs/milling.md, "Time domain"): its JSON, its lines and its
// plots; and of --critical at one speed, the time-domain critical depth beside the accurate method's and the
// zero-order preview. Off the real-time path.
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "config/milling_config.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/cut_job.hpp"
#include "milling/lobes.hpp"

namespace robodamp::milling {

// The cut's verdict, forces, damper and wall as the report's JSON; wall_s: the simulation's wall time.
[[nodiscard]] nlohmann::json cut_json(const CutJob& job, const CutOutcome& o, double wall_s);

// What a person reads of one cut: the speed, depths and verdict, the forces and wall, the damper's use (report:
// cut_json's).
[[nodiscard]] std::string cut_lines(const CutJob& job, const CutOutcome& o, const nlohmann::json& report);

struct CriticalAtSpeed {
  nlohmann::json entry;  // the report's "critical" entry
  std::string line;      // its line
  double depth_mm{0.0};  // the time domain's critical depth
};

// --critical at rpm: the accurate method's depth (its std::invalid_argument, such as a speed the sampled loop
// cannot analyse, a config::ConfigError on --rpm of cfg), the zero-order preview, and the critical depth by
// bisection on simulated cuts of job from the accurate one; progress lines to `progress`.
[[nodiscard]] CriticalAtSpeed critical_at_speed(const config::MillingConfig& cfg, const CutJob& job,
                                                const LobeModel& lobes, const AccurateStability& truth, double rpm,
                                                bool damped, const std::function<void(const std::string&)>& progress);

// --critical's study: critical_at_speed at every speed of the chosen structure (zero-order and accurate models
// with the damper as asked, the cut at radial_mm when given).
struct CriticalStudy {
  config::StructureConfig chosen;  // the job's structure as chosen (--structure, --controller)
  const Structure& structure;      // it open, for the simulated cuts
  CutOverrides overrides;
  std::vector<double> speeds;
  bool damped{false};
  std::optional<double> radial_mm;
};
// The report's "critical" entries, each speed's line on stdout; `more`, when it returns a value, adds it to the
// speed's entry as "hil" (the same cut through the HIL emulator).
[[nodiscard]] nlohmann::json critical_study(
    const config::MillingConfig& cfg, const CriticalStudy& study,
    const std::function<void(const std::string&)>& progress,
    const std::function<nlohmann::json(const CutJob&, double, const CriticalAtSpeed&)>& more);

// Into dir (created): cut_displacement.png, cut_force.png, cut_spectrum.png (the wall-normal displacement
// after settling, tooth-passing harmonics marked) and cut_surface.png (the wall per revolution). An empty
// string, or why a plot failed.
[[nodiscard]] std::string plot_cut(const CutOutcome& o, const std::string& dir);

}  // namespace robodamp::milling
