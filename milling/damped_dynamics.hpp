// The tool's dynamics in a cut with the damper running (docs/milling.md, "Time domain with the damper"):
// the structure's modal tables as exact modal blocks (milling/tool_dynamics.hpp) plus, for each controller
// part, the damping configuration's simulated plant (sim::Plant: the robot's modal model, the actuator of
// Eq. 3 with its delay and its force and voltage limits, the control accelerometer with its noise and
// ADC) closed by the real-time control::Controller (its chain, gain ramp and limits) with one sample of
// computation delay, stepping at the configuration's loop rate. The cutting force acts on the plant at the
// part's location along its direction. The cut steps at the loop period. Off the real-time path (the
// per-step calls are the real-time code paths of the controller and the plant).
#pragma once

#include <memory>
#include <vector>

#include "analysis/loop_model.hpp"
#include "control/controller.hpp"
#include "milling/structure.hpp"
#include "milling/tool_dynamics.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::milling {

// Cutter frame <-> machine frame (Structure::frf_cutter): a feed along +y makes the cutter's x the
// machine's y and its y the machine's -x.
[[nodiscard]] inline Eigen::Vector2d to_machine(const Eigen::Vector2d& c, config::Axis feed) {
  return feed == config::Axis::kX ? c : Eigen::Vector2d(-c(1), c(0));
}
[[nodiscard]] inline Eigen::Vector2d to_cutter(const Eigen::Vector2d& m, config::Axis feed) {
  return feed == config::Axis::kX ? m : Eigen::Vector2d(m(1), -m(0));
}

struct DampingStats {
  double peak_actuator_force_n{0.0};  // transmitted (Eq. 3), after settling
  double peak_coil_force_n{0.0};      // commanded (T V, what actuator.force_limit_n bounds), after settling
  double saturated_s{0.0};            // loop ticks at a controller or actuator limit, after settling
  double loop_rate_hz{0.0};
};

// What drives a controller part's actuator in place of the part's own control::Controller (e.g. the
// supervisor with a speed schedule's sets, switching as the spindle moves): one loop tick, the sampled
// acceleration in, the amplifier command out, and whether a controller limit acted this tick.
class LoopDriver {
 public:
  virtual ~LoopDriver() = default;
  virtual double tick(double accel_mps2, bool& limited) = 0;
};

class DampedDynamics final : public CutDynamics {
 public:
  // The structure's controller parts (loop models) with its modal tables, for a feed along feed_axis.
  // Throws std::invalid_argument without a controller part or with two of different loop rates.
  DampedDynamics(const Structure& structure, config::Axis feed_axis);

  [[nodiscard]] double step_s() const override { return period_s_; }
  [[nodiscard]] Eigen::Vector2d displacement() const override;
  // Linear extrapolation of the last step (the plant has no look-ahead): second order in the step.
  [[nodiscard]] Eigen::Vector2d predict(const Eigen::Vector2d& f_n) const override;
  void step(const Eigen::Vector2d& f_n) override;

  // The first controller part's actuator driven by `driver` (outliving this) instead of its Controller.
  void drive_with(LoopDriver* driver) { driver_ = driver; }
  // The plant's actuator force limit (the first part's), N.
  [[nodiscard]] double actuator_force_limit_n() const;

  // Statistics from now on.
  void settled() override { stats_ = true; }
  [[nodiscard]] const DampingStats& stats() const { return stats_out_; }

 private:
  struct Loop;
  [[nodiscard]] Eigen::Vector2d loops_displacement() const;
  double period_s_{0.0};
  config::Axis feed_axis_;
  std::unique_ptr<ToolDynamics> modal_;  // the modal tables (none: null)
  std::vector<std::shared_ptr<Loop>> loops_;
  Eigen::Vector2d last_{Eigen::Vector2d::Zero()}, previous_{Eigen::Vector2d::Zero()};
  bool stats_{false};
  LoopDriver* driver_{nullptr};
  DampingStats stats_out_;
};

}  // namespace robodamp::milling
