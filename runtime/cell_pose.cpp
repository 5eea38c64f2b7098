// The cell and the robot's pose (pose_schedule): the regions' sets, the hand-over commands and the joints
// the machining monitor's limits are for (runtime/cell.hpp, docs/pose_dynamics.md).
#include <cmath>

#include <spdlog/spdlog.h>

#include "runtime/cell.hpp"

namespace robodamp::runtime {

Status Cell::configure_pose_schedule() {
  pose_schedule_ = {};
  if (!cfg_.pose_schedule) return {};
  try {
    pose_schedule_ = analysis::analyse_pose_schedule(cfg_);
    for (const auto& r : pose_schedule_.regions)
      spdlog::info(
          "pose region '{}': matched at {:.2f} Hz (dominant mode {:.2f}-{:.2f} Hz over {} poses), K = {} N s/m, "
          "polarity {}, K_max {:.0f} N s/m",
          r.name, r.dominant_hz, r.dominant_min_hz, r.dominant_max_hz, r.grid_poses, r.gain_ns_per_m, r.polarity,
          r.k_max_ns_per_m);
    if (!o_.pose_deg.empty())
      if (auto p = config::pose_problem(pose_schedule_.model, o_.pose_deg))
        throw config::ConfigError({config::Problem{cfg_.source, {}, "--pose", *p}});
  } catch (const config::ConfigError& e) {
    return {StatusKind::kConfigError, e.what()};
  }
  return {};
}

std::vector<double> Cell::robot_pose_deg() const {
  std::vector<double> q = o_.pose_deg;  // the simulated robot stands there
  if (joint_pose_)
    q = joint_pose_->joints_deg();
  else if (modbus_ && cfg_.modbus->robot.joints_register >= 0)
    q = modbus_->client().joints_deg();
  for (const double v : q)
    if (!std::isfinite(v)) return {};  // a joint not available: the pose is not known
  return q;
}

std::optional<dds::SpectrumSample> Cell::spectrum_at_pose() {
  std::optional<dds::SpectrumSample> s = spectrum_->next();
  if (!s || !cfg_.pose_schedule || pose_schedule_.regions.empty()) return s;
  const std::vector<double> q = robot_pose_deg();
  if (q.empty()) return s;  // not known: the configuration's table
  try {
    const analysis::PoseModes pm =
        analysis::pose_modes(pose_schedule_.model, q, cfg_.pose_schedule->axis, cfg_.pose_schedule->modes);
    s->mode_hz.clear();
    for (const auto& m : pm.modes) s->mode_hz.push_back(static_cast<float>(m.natural_freq_hz));
  } catch (const std::exception&) {  // a pose outside the model's travel: the configuration's table
  }
  return s;
}

void Cell::post_pose_region(std::optional<std::size_t> region) {
  const double set = region ? static_cast<double>(*region) : -1.0;
  if (!loop_->post({rt::CommandKind::kSetPoseRegion, set}))
    spdlog::warn("the robot's pose moved: the command queue is full, dropped");
}

}  // namespace robodamp::runtime
