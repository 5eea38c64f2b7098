#include "milling/damped_dynamics.hpp"

#include <cmath>
#include <stdexcept>

namespace robodamp::milling {

struct DampedDynamics::Loop {
  std::shared_ptr<const analysis::LoopModel> model;
  std::size_t location{0}, direction{1};
  std::unique_ptr<sim::Plant> plant;
  std::unique_ptr<control::Controller> controller;
  sim::HeldForce* cutting{nullptr};  // the cutting force on the robot at the part's location, set each tick
  double command_v{0.0};
};

DampedDynamics::DampedDynamics(const Structure& structure, config::Axis feed_axis) : feed_axis_(feed_axis) {
  for (const auto& part : structure.controller_parts()) {
    if (part.across)
      throw std::invalid_argument("DampedDynamics: a controller part across the plane (not simulated in time)");
    auto loop = std::make_shared<Loop>();
    loop->model = part.model;
    loop->location = part.location;
    loop->direction = part.direction;
    loop->plant = std::make_unique<sim::Plant>(part.model->plant(), part.model->config());
    auto force = std::make_unique<sim::HeldForce>(part.location);
    loop->cutting = force.get();
    loop->plant->add_excitation(std::move(force));
    control::ControllerParams params = part.model->chain().params;
    params.gain_ns_per_m = part.gain_ns_per_m;
    params.polarity = part.polarity;
    loop->controller = std::make_unique<control::Controller>(params);
    const double period = loop->plant->period_s();
    if (period_s_ > 0.0 && std::abs(period - period_s_) > 1e-12 * period)
      throw std::invalid_argument("DampedDynamics: controller parts with different loop rates");
    period_s_ = period;
    stats_out_.loop_rate_hz = 1.0 / period;
    loops_.push_back(std::move(loop));
  }
  if (loops_.empty()) throw std::invalid_argument("DampedDynamics: the structure has no controller part");
  // The modal tables only: the controller parts' robot is the plants'.
  Structure tables(structure.modal_terms_by_pair(), structure.name());
  if (const auto terms = cutter_modal_terms(tables, feed_axis); !terms.empty())
    modal_ = std::make_unique<ToolDynamics>(terms, period_s_);
}

double DampedDynamics::actuator_force_limit_n() const { return loops_.front()->model->config().actuator.force_limit_n; }

Eigen::Vector2d DampedDynamics::loops_displacement() const {
  Eigen::Vector2d machine = Eigen::Vector2d::Zero();
  for (const auto& l : loops_)
    machine(static_cast<Eigen::Index>(l->direction)) += l->plant->displacement_m(l->location);
  return to_cutter(machine, feed_axis_);
}

Eigen::Vector2d DampedDynamics::displacement() const {
  return loops_displacement() + (modal_ ? modal_->displacement() : Eigen::Vector2d::Zero());
}

Eigen::Vector2d DampedDynamics::predict(const Eigen::Vector2d&) const { return 2.0 * last_ - previous_; }

void DampedDynamics::step(const Eigen::Vector2d& f_cutter) {
  const Eigen::Vector2d f_machine = to_machine(f_cutter, feed_axis_);
  for (const auto& l : loops_) {
    // One loop tick: sample, compute; the command reaches the amplifier at the next tick.
    const sim::SensorReading s = l->plant->sense();
    bool limited = false;
    double next = 0.0;
    if (driver_ != nullptr && l == loops_.front()) {
      next = driver_->tick(s.accel_mps2, limited);
    } else {
      const auto c0 = l->controller->counters();
      next = l->controller->update(s.accel_mps2);
      const auto& c1 = l->controller->counters();
      limited = c1.force_limited + c1.voltage_limited + c1.slew_limited >
                c0.force_limited + c0.voltage_limited + c0.slew_limited;
    }
    const auto p0 = l->plant->counters().force_limited + l->plant->counters().voltage_clipped;
    l->cutting->value_n = f_machine(static_cast<Eigen::Index>(l->direction));
    l->plant->step(l->command_v);
    l->command_v = next;
    if (stats_) {
      const bool clipped = l->plant->counters().force_limited + l->plant->counters().voltage_clipped > p0;
      if (limited || clipped) stats_out_.saturated_s += period_s_;
      stats_out_.peak_actuator_force_n =
          std::max(stats_out_.peak_actuator_force_n, std::abs(l->plant->actuator_force_n()));
      stats_out_.peak_coil_force_n =
          std::max(stats_out_.peak_coil_force_n, std::abs(l->command_v) * l->model->config().actuator.constant_n_per_v);
    }
  }
  if (modal_) modal_->step(f_cutter);
  previous_ = last_;
  last_ = displacement();
}

}  // namespace robodamp::milling
