#include "runtime/parameter_requests.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "control/controller.hpp"

namespace robodamp::runtime {

namespace {

CheckedRequest check_gain(const rt::Supervisor& sup, const config::Config& cfg, double value) {
  char b[256];
  const std::size_t set = sup.active_parameter_set();
  if (sup.controller().in_speed_band()) {
    std::snprintf(b, sizeof b,
                  "gain_ns_per_m = %g N s/m is refused: at %g rpm the spindle speed sets K (controller.speed_schedule, "
                  "band %zu: K %g N s/m, never worse than no damper); disarm to take the damper out",
                  value, sup.controller().schedule_rpm(),
                  sup.controller().params().speed_band_of(sup.controller().schedule_rpm()),
                  sup.controller().target_gain_ns_per_m());
    return {{false, b}, {}};
  }
  const double limit = std::min(sup.gain_limit_ns_per_m(), control::kMaxGainNsPerM);
  std::snprintf(b, sizeof b, "supervision.max_gain_fraction = %g x the analysed maximum stable K of parameter set %zu",
                cfg.supervision.max_gain_fraction, set);
  if (auto problem = config::gain_request_problem(value, limit, b)) return {{false, *problem}, {}};
  std::snprintf(b, sizeof b, "K ramps to %g N s/m over controller.gain_ramp_s = %g s", value,
                cfg.controller.gain_ramp_s);
  return {{true, b}, {rt::CommandKind::kSetGain, value}};
}

CheckedRequest check_select(const rt::Supervisor& sup, const config::Config& cfg, double value) {
  const auto& sets = sup.parameter_sets();
  if (sup.controller().params().speed_chooses_set()) {
    char b[200];
    std::snprintf(b, sizeof b,
                  "parameter_set = %g is refused: the spindle speed chooses the set (controller.speed_schedule; "
                  "set %zu runs at %g rpm)",
                  value, sup.active_parameter_set(), sup.controller().schedule_rpm());
    return {{false, b}, {}};
  }
  if (!(value >= 0.0 && value == std::floor(value) && value < static_cast<double>(sets.size()))) {
    char b[256];
    std::snprintf(b, sizeof b,
                  "parameter_set = %g is not a configured set: allowed 0 <= value <= %zu (0 = %s, then parameter_sets)",
                  value, sets.size() - 1, cfg.source.c_str());
    return {{false, b}, {}};
  }
  const auto idx = static_cast<std::size_t>(value);
  if (!sets[idx].analysis_stable)
    return {{false, "parameter set " + std::to_string(idx) + ": the analysis finds its loop unstable"}, {}};
  return {{true, "parameter set " + std::to_string(idx) + " is handed over at the next tick (fade out, swap, fade in)"},
          {rt::CommandKind::kSelectParams, value}};
}

CheckedRequest check_enable(double value) {
  if (value != 0.0 && value != 1.0) {
    char b[128];
    std::snprintf(b, sizeof b, "enable = %g is out of range: allowed 0 (disarm) or 1 (arm)", value);
    return {{false, b}, {}};
  }
  if (value == 1.0)
    return {{true,
             "arming: the supervisor checks the sensor, the actuator path and the analysis at the next tick "
             "(the status topic shows the outcome)"},
            {rt::CommandKind::kArm, 0.0}};
  return {{true, "disarming: the command fades out over controller.gain_ramp_s"}, {rt::CommandKind::kDisarm, 0.0}};
}

CheckedRequest check_reset(const rt::Supervisor& sup) {
  if (sup.observed_state() != rt::State::kFault)
    return {{false, std::string("reset: nothing to reset, the loop is ") + rt::to_string(sup.observed_state()) +
                        " (a reset clears a latched trip)"},
            {}};
  return {{true, std::string("reset: the trip (") + rt::to_string(sup.observed_trip()) +
                     ") clears once the safe-state ramp is over; the loop is then disabled: arm it to damp again"},
          {rt::CommandKind::kResetFault, 0.0}};
}

CheckedRequest check_spindle(const config::Config& cfg, double rpm) {
  char b[256];
  if (!(std::isfinite(rpm) && rpm >= 0.0 && rpm <= cfg.spindle.rpm_max)) {
    std::snprintf(b, sizeof b, "spindle_rpm = %g rpm is out of range: allowed 0 <= value <= spindle.rpm_max = %g rpm",
                  rpm, cfg.spindle.rpm_max);
    return {{false, b}, {}};
  }
  if (cfg.controller.harmonic_notch)
    std::snprintf(b, sizeof b,
                  "the harmonic notches follow %g rpm x %d teeth = %g Hz (below controller.harmonic_notch.min_hz "
                  "= %g Hz they park)",
                  rpm, cfg.spindle.teeth, rpm * cfg.spindle.teeth / 60.0, cfg.controller.harmonic_notch->min_hz);
  else
    std::snprintf(b, sizeof b, "spindle at %g rpm noted (no controller.harmonic_notch is configured)", rpm);
  return {{true, b}, {rt::CommandKind::kSetSpindle, rpm}};
}

}  // namespace

CheckedRequest check_request(const rt::Supervisor& sup, const config::Config& cfg, dds::RequestKind kind,
                             double value) {
  switch (kind) {
    case dds::RequestKind::kSetGain:
      return check_gain(sup, cfg, value);
    case dds::RequestKind::kSelectParameterSet:
      return check_select(sup, cfg, value);
    case dds::RequestKind::kEnable:
      return check_enable(value);
    case dds::RequestKind::kResetFault:
      return check_reset(sup);
    case dds::RequestKind::kSetSpindleRpm:
      return check_spindle(cfg, value);
  }
  return {{false, "unknown request kind"}, {}};
}

}  // namespace robodamp::runtime
