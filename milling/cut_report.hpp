// What `robodamp cut` reports of one simulated cut (docs/milling.md, "Time domain"): its JSON and its plots.
// Off the real-time path.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "milling/cut_job.hpp"

namespace robodamp::milling {

// The cut's verdict, forces, damper and wall as the report's JSON; wall_s: the simulation's wall time.
[[nodiscard]] nlohmann::json cut_json(const CutJob& job, const CutOutcome& o, double wall_s);

// Into dir (created): cut_displacement.png, cut_force.png, cut_spectrum.png (the wall-normal displacement
// after settling, tooth-passing harmonics marked) and cut_surface.png (the wall per revolution). An empty
// string, or why a plot failed.
[[nodiscard]] std::string plot_cut(const CutOutcome& o, const std::string& dir);

}  // namespace robodamp::milling
