#include "analysis/pose_mode_check.hpp"

#include <cmath>
#include <limits>

#include "analysis/pose_schedule.hpp"

namespace robodamp::analysis {

namespace {

// The index of the mode nearest in frequency, within 25 %; -1 when none.
int nearest(const std::vector<config::ModeConfig>& modes, double f_hz) {
  int best = -1;
  double d_best = std::log(1.25);
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const double d = std::abs(std::log(modes[i].natural_freq_hz / f_hz));
    if (d < d_best) d_best = d, best = static_cast<int>(i);
  }
  return best;
}

}  // namespace

std::vector<ModeCheckRow> check_pose_modes(const config::RobotModelConfig& prior,
                                           const config::RobotModelConfig& mapped,
                                           const std::vector<config::MeasuredPoseModes>& poses, bool held_out, int axis,
                                           int count) {
  std::vector<ModeCheckRow> rows;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const config::MeasuredPoseModes& p : poses) {
    const PoseModes a = pose_modes(prior, p.joints_deg, axis, count), b = pose_modes(mapped, p.joints_deg, axis, count);
    for (const config::ModeConfig& m : p.modes) {
      ModeCheckRow r;
      r.pose = p.name;
      r.joints_deg = p.joints_deg;
      r.held_out = held_out;
      r.measured_hz = m.natural_freq_hz;
      r.measured_damping_ratio = m.damping_ratio;
      r.measured_stiffness_n_per_m = m.stiffness_n_per_m;
      const int i = nearest(a.modes, m.natural_freq_hz), j = nearest(b.modes, m.natural_freq_hz);
      r.model_hz = i < 0 ? nan : a.modes[static_cast<std::size_t>(i)].natural_freq_hz;
      r.model_stiffness_n_per_m = i < 0 ? nan : a.modes[static_cast<std::size_t>(i)].stiffness_n_per_m;
      r.mapped_hz = r.mapped_damping_ratio = r.mapped_stiffness_n_per_m = nan;
      r.freq_sigma_pct = r.damping_sigma_pct = r.stiffness_sigma_pct = nan;
      if (j >= 0) {
        const auto& mm = b.modes[static_cast<std::size_t>(j)];
        r.mapped_hz = mm.natural_freq_hz;
        r.mapped_damping_ratio = mm.damping_ratio;
        r.mapped_stiffness_n_per_m = mm.stiffness_n_per_m;
        if (static_cast<std::size_t>(j) < b.corrections.size()) {
          const auto& c = b.corrections[static_cast<std::size_t>(j)];
          r.freq_sigma_pct = 100.0 * c.freq_sigma;
          r.damping_sigma_pct = 100.0 * c.damping_sigma;
          r.stiffness_sigma_pct = 100.0 * c.stiffness_sigma;
        }
      }
      r.nearest_measured_deg = b.nearest_measured_deg;
      rows.push_back(std::move(r));
    }
  }
  return rows;
}

std::vector<ModeSweepPoint> sweep_pose_modes(const config::RobotModelConfig& prior,
                                             const config::RobotModelConfig& mapped,
                                             const std::vector<double>& base_deg, std::size_t joint, int steps,
                                             int axis, int count) {
  std::vector<ModeSweepPoint> out;
  const config::RobotJointConfig& j = mapped.joints.at(joint);
  for (int i = 0; i < steps; ++i) {
    std::vector<double> q = base_deg;
    q[joint] = j.min_deg + (j.max_deg - j.min_deg) * i / (steps - 1);
    ModeSweepPoint p;
    p.joint_deg = q[joint];
    const PoseModes a = pose_modes(prior, q, axis, count), b = pose_modes(mapped, q, axis, count);
    for (std::size_t k = 0; k < b.modes.size(); ++k) {
      // The model's mode this one follows: the same index in the picture (a mode the measurements alone give
      // has none; drawing the model's k-th there paired a 1 Hz mode of a fitted model with a 9 Hz measured one).
      const bool followed = k < b.corrections.size() && !b.corrections[k].measured_only() &&
                            static_cast<std::size_t>(b.corrections[k].model_index) < a.modes.size();
      p.model_hz.push_back(followed ? a.modes[static_cast<std::size_t>(b.corrections[k].model_index)].natural_freq_hz
                                    : std::numeric_limits<double>::quiet_NaN());
      p.mapped_hz.push_back(b.modes[k].natural_freq_hz);
      p.freq_sigma_pct.push_back(k < b.corrections.size() ? 100.0 * b.corrections[k].freq_sigma : 0.0);
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace robodamp::analysis
