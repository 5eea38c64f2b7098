#include "runtime/joint_state_pose.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "units/units.hpp"

namespace robodamp::runtime {

JointStatePose::JointStatePose(config::JointStatesConfig cfg, config::PoseScheduleConfig schedule,
                               std::function<void(std::optional<std::size_t>)> on_region)
    : cfg_(std::move(cfg)), schedule_(std::move(schedule)), on_region_(std::move(on_region)) {}

void JointStatePose::on_message(const std::vector<std::string>& names, const std::vector<double>& position_rad,
                                Clock::time_point now) {
  std::lock_guard lock(m_);
  ++n_.messages;
  std::string problem;
  std::vector<double> q(cfg_.names.size());
  if (names.size() != position_rad.size())
    problem = std::to_string(names.size()) + " names and " + std::to_string(position_rad.size()) + " positions";
  for (std::size_t i = 0; i < cfg_.names.size() && problem.empty(); ++i) {
    const auto at = std::find(names.begin(), names.end(), cfg_.names[i]);
    if (at == names.end())
      problem = "no joint '" + cfg_.names[i] + "'";
    else if (const double rad = position_rad[static_cast<std::size_t>(at - names.begin())]; !std::isfinite(rad))
      problem = "joint '" + cfg_.names[i] + "' is not finite";
    else
      q[i] = rad * kDegPerRad;
  }
  last_ = now, heard_ = true, lost_ = false;  // heard, even when refused: not a silence
  if (!problem.empty()) {
    ++n_.refused;
    if (problem != last_problem_)  // once per kind of problem, not 50 times a second
      spdlog::warn("dds joint states on {}: a message with {} (dds.joint_states.names): the pose is unknown",
                   cfg_.topic, problem);
    last_problem_ = problem;
    joints_deg_.clear();
    settling_.restart();
    if (settling_.settled(-1, 1)) report(-1);
    return;
  }
  last_problem_.clear();
  joints_deg_ = q;
  const auto region = config::region_of(schedule_, q.data(), q.size(), settling_.current());
  if (!region) ++n_.out_of_map;
  if (settling_.settled(region ? static_cast<long>(*region) : -1, cfg_.settle_samples))
    report(region ? static_cast<long>(*region) : -1);
}

void JointStatePose::check(Clock::time_point now) {
  std::lock_guard lock(m_);
  if (!heard_ || lost_ || now - last_ < std::chrono::duration<double>(cfg_.timeout_s)) return;
  lost_ = true;
  joints_deg_.clear();
  ++n_.losses;
  spdlog::warn("dds joint states on {}: none for {} s: the pose is unknown", cfg_.topic, cfg_.timeout_s);
  settling_.restart();
  if (settling_.settled(-1, 1)) report(-1);
}

void JointStatePose::report(long region) {
  ++n_.changes;
  if (region >= 0)
    spdlog::info("dds joint states: pose {} in region '{}'", config::describe_pose(joints_deg_),
                 schedule_.regions[static_cast<std::size_t>(region)].name);
  else if (!lost_ && last_problem_.empty())
    spdlog::warn("dds joint states: the pose {} is out of the map (outside every region of pose_schedule)",
                 config::describe_pose(joints_deg_));
  if (on_region_) on_region_(region >= 0 ? std::optional(static_cast<std::size_t>(region)) : std::nullopt);
}

std::vector<double> JointStatePose::joints_deg() const {
  std::lock_guard lock(m_);
  return joints_deg_;
}

JointStateCounters JointStatePose::counters() const {
  std::lock_guard lock(m_);
  return n_;
}

}  // namespace robodamp::runtime
