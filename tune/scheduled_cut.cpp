#include "tune/scheduled_cut.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "control/controller.hpp"
#include "milling/cut_job.hpp"
#include "milling/damped_dynamics.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::tune {

bool ScheduledCut::all_stable() const {
  return !segments.empty() &&
         std::all_of(segments.begin(), segments.end(), [](const auto& s) { return s.verdict.stable; });
}

bool ScheduledCut::switches_within_limits() const {
  return std::all_of(segments.begin(), segments.end(), [&](const auto& s) {
    return s.switch_limited_ticks == 0 && s.switch_peak_force_n < force_limit_n && s.trip == "none";
  });
}

namespace {

// The loop tick as the cell runs it: the supervisor (with the controller inside) on a fresh, valid sample
// and a ready amplifier, an operator command posted for the next tick.
class SupervisedLoop final : public milling::LoopDriver {
 public:
  SupervisedLoop(rt::Supervisor& sup, double fs_hz) : sup_(sup), dt_s_(1.0 / fs_hz) {}
  double tick(double accel_mps2, bool& limited) override {
    rt::TickInput in;
    in.dt_s = dt_s_;
    in.accel_mps2 = accel_mps2;
    in.fresh = true;
    in.amplifier_ready = true;
    in.command = pending_;
    pending_ = {};
    const control::ControllerCounters before = sup_.controller().counters();
    const rt::TickOutput out = sup_.step(in);
    const control::ControllerCounters& after = sup_.controller().counters();
    limited = after.force_limited + after.voltage_limited + after.slew_limited >
              before.force_limited + before.voltage_limited + before.slew_limited;
    limited_ticks += limited ? 1U : 0U;
    peak_force_n = std::max(peak_force_n, std::abs(sup_.controller().force_command_n()));
    lowest_derate = std::min(lowest_derate, sup_.controller().derate());
    if (out.derated) derated_s += dt_s_;
    time_s += dt_s_;
    if (out.trip != rt::Trip::kNone && trip_s < 0.0) trip_s = time_s;
    return out.command_v;
  }
  void post(rt::OperatorCommand c) { pending_ = c; }
  std::uint64_t limited_ticks{0};
  double peak_force_n{0.0};
  double lowest_derate{1.0}, derated_s{0.0};
  double time_s{0.0}, trip_s{-1.0};

 private:
  rt::Supervisor& sup_;
  double dt_s_;
  rt::OperatorCommand pending_{};
};

// The cell's sets as the runtime builds them: set 0 its own chain with the bands, set i the schedule's
// controllers[i - 1] (config::speed_controller_config), each with its analysis verdict.
std::unique_ptr<rt::Supervisor> scheduled_supervisor(const config::Config& cell) {
  const analysis::LoopModel m0(cell);
  const int pol = cell.controller.polarity;
  const auto k0 = analysis::max_stable_gain(m0, pol);
  auto sup =
      std::make_unique<rt::Supervisor>(config::supervisor_settings(cell, m0.stable(cell.controller.gain_ns_per_m, pol),
                                                                   k0.value_or(control::kMaxGainNsPerM)),
                                       m0.chain().params);
  const std::size_t controllers =
      cell.controller.speed_schedule ? cell.controller.speed_schedule->controllers.size() : 0;
  for (std::size_t i = 1; i <= controllers; ++i) {
    const config::Config c = config::speed_controller_config(cell, i);
    const analysis::LoopModel m(c);
    const auto k = analysis::max_stable_gain(m, c.controller.polarity);
    (void)sup->add_parameter_set({m.chain().params, true, k.value_or(control::kMaxGainNsPerM), 0.0});
  }
  return sup;
}

constexpr double kRingDownS = 3.0;  // out of the cut after each cut, before the next speed change

void idle(milling::DampedDynamics& dyn, double seconds) {
  const auto n = static_cast<long>(std::ceil(seconds / dyn.step_s()));
  for (long i = 0; i < n; ++i) dyn.step(Eigen::Vector2d::Zero());
}

// Out of the cut until the switch is over (no hand-over pending, K at its target), at most limit_s; the time.
double settle_switch(milling::DampedDynamics& dyn, const rt::Supervisor& sup, double limit_s) {
  double t = 0.0;
  idle(dyn, 2.0 * dyn.step_s());  // the command reaches the supervisor at the next tick
  while (t < limit_s && (sup.controller().handover_pending() ||
                         std::abs(sup.controller().gain_ns_per_m() - sup.controller().target_gain_ns_per_m()) > 1e-9)) {
    idle(dyn, 0.01);
    t += 0.01;
  }
  return t;
}

}  // namespace

ScheduledCut scheduled_cut(const config::Config& cell, const config::MillingConfig& job,
                           const std::vector<ScheduledCutStep>& steps, int revolutions) {
  if (!cell.controller.speed_schedule)
    throw std::invalid_argument("scheduled_cut: the configuration has no speed schedule");
  SupervisedCutOptions o;
  o.revolutions = revolutions;
  return supervised_cut(cell, job, steps, o);
}

// long: the cell armed, then each step's switch, cut and ring-down in the order a machinist runs them
ScheduledCut supervised_cut(const config::Config& cell, const config::MillingConfig& job,
                            const std::vector<ScheduledCutStep>& steps, const SupervisedCutOptions& opt) {
  const int revolutions = opt.revolutions;
  const std::unique_ptr<rt::Supervisor> sup = scheduled_supervisor(cell);
  const auto model = std::make_shared<const analysis::LoopModel>(opt.plant ? *opt.plant : cell);
  const milling::Structure damped(job.selected_structure(), true,
                                  {model, cell.controller.gain_ns_per_m, cell.controller.polarity});
  milling::DampedDynamics dyn(damped, job.cut.feed_axis);
  SupervisedLoop loop(*sup, cell.loop.rate_hz);
  dyn.drive_with(&loop);
  ScheduledCut out;
  out.force_limit_n = dyn.actuator_force_limit_n();
  // Arm once the sensor is live (arming_live_cycles fresh samples), then let the fade-in finish.
  idle(dyn, (cell.supervision.arming_live_cycles + 10) / cell.loop.rate_hz);
  loop.post({rt::CommandKind::kArm, 0.0});
  idle(dyn, cell.controller.gain_ramp_s + 0.2);
  for (const ScheduledCutStep& step : steps) {
    milling::CutOverrides o;
    o.rpm = step.rpm;
    o.axial_mm = step.depth_mm;
    o.damped = true;
    o.revolutions = revolutions + job.time_domain.settle_revolutions;
    milling::CutJob cut = milling::make_cut_job(job, damped, o);
    cut.settings.settle_revolutions = job.time_domain.settle_revolutions;
    ScheduledCutSegment s;
    loop.limited_ticks = 0;
    loop.peak_force_n = 0.0;
    loop.post({rt::CommandKind::kSetSpindle, cut.settings.rpm});
    s.switch_s = settle_switch(dyn, *sup, 20.0);
    s.switch_peak_force_n = loop.peak_force_n;
    s.switch_limited_ticks = loop.limited_ticks;
    loop.limited_ticks = 0;
    loop.peak_force_n = 0.0;
    loop.lowest_derate = 1.0;
    loop.derated_s = 0.0;
    loop.time_s = 0.0;
    const milling::CutOutcome r = milling::run_cut(dyn, cut.cutter, cut.material, cut.settings);
    s.lowest_derate = loop.lowest_derate;
    s.derated_s = loop.derated_s;
    s.trip_s = loop.trip_s;
    s.peak_force_command_n = loop.peak_force_n;
    s.limited_ticks = loop.limited_ticks;
    // The tool leaves the cut (here at once: the static deflection is released) and the structure rings down
    // before the next speed change.
    idle(dyn, kRingDownS);
    s.rpm = cut.settings.rpm;
    s.depth_mm = step.depth_mm;
    s.set = sup->active_parameter_set();
    s.gain_ns_per_m = sup->controller().target_gain_ns_per_m();
    s.verdict = r.verdict;
    s.state = rt::to_string(sup->observed_state());
    s.trip = rt::to_string(sup->observed_trip());
    out.segments.push_back(s);
    if (sup->observed_trip() != rt::Trip::kNone) break;
  }
  out.counters = sup->counters();
  out.handovers = sup->counters().speed_handovers;
  out.handovers_refused = sup->counters().speed_handovers_refused;
  return out;
}

}  // namespace robodamp::tune
