#include "runtime/path_ahead.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "units/units.hpp"

namespace robodamp::runtime {

PathAhead::PathAhead(config::PathAheadConfig cfg, std::vector<std::string> names)
    : cfg_(std::move(cfg)), names_(std::move(names)) {}

void PathAhead::on_message(const std::vector<std::string>& joint_names, const std::vector<TrajectoryPoint>& points,
                           Clock::time_point now) {
  std::string problem;
  std::vector<std::size_t> column(names_.size());
  for (std::size_t i = 0; i < names_.size() && problem.empty(); ++i) {
    const auto at = std::find(joint_names.begin(), joint_names.end(), names_[i]);
    if (at == joint_names.end())
      problem = "no joint '" + names_[i] + "'";
    else
      column[i] = static_cast<std::size_t>(at - joint_names.begin());
  }
  std::vector<Due> path;
  for (std::size_t k = 0; k < points.size() && problem.empty(); ++k) {
    const TrajectoryPoint& p = points[k];
    if (p.position_rad.size() != joint_names.size()) {
      problem = "point " + std::to_string(k) + " with " + std::to_string(p.position_rad.size()) + " positions for " +
                std::to_string(joint_names.size()) + " joints";
      break;
    }
    if (!(std::isfinite(p.time_from_start_s) && p.time_from_start_s >= 0.0)) {
      problem = "point " + std::to_string(k) + " due at " + std::to_string(p.time_from_start_s) + " s";
      break;
    }
    Due d;
    for (const std::size_t c : column) {
      if (!std::isfinite(p.position_rad[c])) {
        problem = "point " + std::to_string(k) + ": joint '" + joint_names[c] + "' is not finite";
        break;
      }
      d.joints_deg.push_back(p.position_rad[c] * kDegPerRad);
    }
    const double ahead_s = p.time_from_start_s > 0.0 ? p.time_from_start_s : cfg_.hold_s;
    d.until = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(ahead_s));
    path.push_back(std::move(d));
  }
  std::lock_guard lock(m_);
  ++n_.messages;
  if (!problem.empty()) {
    ++n_.refused;
    if (problem != last_problem_)
      spdlog::warn("dds path ahead on {}: a trajectory with {} (dds.path_ahead.names): refused, the last path kept",
                   cfg_.topic, problem);
    last_problem_ = problem;
    return;
  }
  last_problem_.clear();
  path_ = std::move(path);
}

std::vector<std::vector<double>> PathAhead::poses_deg(Clock::time_point now) const {
  std::lock_guard lock(m_);
  std::vector<std::vector<double>> out;
  for (const Due& d : path_)
    if (now < d.until) out.push_back(d.joints_deg);
  return out;
}

PathAheadCounters PathAhead::counters() const {
  std::lock_guard lock(m_);
  return n_;
}

}  // namespace robodamp::runtime
