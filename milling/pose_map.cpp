#include "milling/pose_map.hpp"

#include <algorithm>
#include <cmath>

#include "milling/accurate_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"
#include "robot/robot_model.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

namespace {

// The job's minimum limiting depth over its speed range with the robot at pose q, and its speed.
std::pair<double, double> job_minimum(const config::MillingConfig& job, const std::vector<double>& q, bool zero_order) {
  config::StructureConfig st = *job.find_structure(job.structure);
  for (auto& part : st.parts)
    if (part.pose) part.pose->joints_deg = q;
  const Structure structure(st, false);
  if (zero_order) {
    const auto lobes = LobeModel(structure, chatter_process(job.tool, job.material, job.cut), job.lobes).diagram();
    return {lobes.minimum.b_lim_mm, lobes.minimum.rpm};
  }
  const AccurateDiagram d = accurate_diagram(structure, job);
  return {d.minimum.critical_depth_mm, d.minimum.rpm};
}

}  // namespace

PoseMap pose_map(const config::RobotModelConfig& m, const PoseMapRequest& req,
                 const std::function<void(int, int)>& progress) {
  if (req.job) {
    bool has_pose = false;
    for (const auto& part : req.job->find_structure(req.job->structure)->parts)
      has_pose = has_pose || part.pose.has_value();
    if (!has_pose)
      throw config::ConfigError(
          {config::Problem{req.job->source,
                           {},
                           "structures",
                           "--job: the job's structure has no robot pose part (pose: {model, joints_deg})"}});
  }
  PoseMap out;
  out.f1_min_hz = INFINITY;
  out.min_depth_min_mm = INFINITY;
  if (req.job) out.method = req.zero_order ? "zero-order preview" : "SDM";
  const auto& ja = m.joints[req.joint_a];
  const auto& jb = m.joints[req.joint_b];
  for (int i = 0; i < req.steps; ++i) {
    for (int k = 0; k < req.steps; ++k) {
      std::vector<double> q = req.base_deg;
      q[req.joint_a] = ja.min_deg + (ja.max_deg - ja.min_deg) * i / (req.steps - 1);
      q[req.joint_b] = jb.min_deg + (jb.max_deg - jb.min_deg) * k / (req.steps - 1);
      const auto md = robot::at_pose(m, q).modes(1);
      out.f1_min_hz = std::min(out.f1_min_hz, md[0].freq_hz), out.f1_max_hz = std::max(out.f1_max_hz, md[0].freq_hz);
      PoseMapPoint p{q, md[0].freq_hz, md[0].tcp_modal_stiffness_n_per_m, std::nullopt, std::nullopt};
      if (req.job) {
        const auto [depth_mm, rpm] = job_minimum(*req.job, q, req.zero_order);
        out.min_depth_min_mm = std::min(out.min_depth_min_mm, depth_mm);
        out.min_depth_max_mm = std::max(out.min_depth_max_mm, depth_mm);
        p.min_depth_mm = depth_mm, p.min_depth_rpm = rpm;
      }
      out.grid.push_back(std::move(p));
    }
    if (req.job && progress) progress(i + 1, req.steps);
  }
  return out;
}

}  // namespace robodamp::milling
