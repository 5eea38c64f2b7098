#include "runtime/run_to_end.hpp"

#include <spdlog/spdlog.h>

#include "rt/signals.hpp"
#include "runtime/cell.hpp"
#include "sim_plant/fault_text.hpp"

namespace robodamp::runtime {

namespace {

int exit_status(const Status& s) { return s.kind == StatusKind::kConfigError ? 2 : 1; }

// The request's refusals before anything runs: a speed the loop would refuse, a pose without a schedule, a
// fault drill's text. False, with the reason on `err`.
bool checked(const RunRequest& a, const config::Config& cfg, std::vector<sim::Fault>& faults, std::ostream& err) {
  if (a.spindle_rpm > cfg.spindle.rpm_max) {
    err << "robodamp run: --spindle-rpm = " << a.spindle_rpm
        << " rpm is above spindle.rpm_max = " << cfg.spindle.rpm_max << " rpm of " << a.config_path
        << " (allowed 0 <= value <= " << cfg.spindle.rpm_max << " rpm)\n";
    return false;
  }
  if ((!a.pose_deg.empty() || a.no_pose_schedule) && !cfg.pose_schedule) {
    err << "robodamp run: --pose and --no-pose-schedule need a configuration with pose_schedule\n";
    return false;
  }
  for (const auto& text : a.faults) {
    sim::Fault f;
    if (std::string e; !sim::parse_fault(text, a.duration_s, f, e)) {
      err << "robodamp run: --fault = " << e << '\n';
      return false;
    }
    faults.push_back(f);
  }
  return true;
}

}  // namespace

RunOutcome run_to_end(const RunRequest& a, std::ostream& err) {
  config::Config cfg = config::load_config_file(a.config_path);
  if (a.no_harmonic_notch) cfg.controller.harmonic_notch.reset();
  if (!a.job_path.empty()) cfg.spindle.job = cfg.spindle.job_resolved = a.job_path;
  CellOptions o;
  if (!a.clock.empty()) o.clock = a.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  o.impact_every_s = a.impact_every_s;
  o.record_path = a.record_path;
  o.pose_deg = a.pose_deg;
  o.pose_schedule_off = a.no_pose_schedule;
  std::vector<sim::Fault> faults;
  if (!checked(a, cfg, faults, err)) return {std::nullopt, 2};
  Cell cell(cfg, o);
  if (Status s = cell.configure(); !s.ok()) {
    err << s.message << '\n';
    return {std::nullopt, exit_status(s)};
  }
  if (!faults.empty() && cell.hardware()) {
    err << "robodamp run: --fault needs the simulated plant (this configuration runs the hardware)\n";
    return {std::nullopt, 2};
  }
  for (const auto& f : faults) cell.plant().faults().add(f);
  if (a.spindle_rpm > 0.0) cell.schedule(1, {rt::CommandKind::kSetSpindle, a.spindle_rpm});
  rt::install_shutdown_handlers();
  spdlog::info("robodamp run: {} at {} Hz on the {} clock for {} s against {} (Ctrl-C ends it through the safe state)",
               a.config_path, cfg.loop.rate_hz, config::to_string(cell.config().loop.clock), a.duration_s,
               cell.hardware() ? "the hardware" : "the simulated plant");
  if (Status s = cell.activate(a.duration_s); !s.ok()) {
    err << "robodamp run: " << s.message << '\n';
    return {std::nullopt, exit_status(s)};
  }
  cell.wait();
  if (Status s = cell.deactivate(); !s.ok()) err << "robodamp run: " << s.message << '\n';
  return {cell.summary(), 0};
}

int run_exit_status(const RunSummary& s, std::ostream& err) {
  if (s.record_errors > 0) return 1;
  if (s.trip == "signal") return 0;
  if (s.trip != "none") return 4;
  if (s.never_armed()) {
    err << "robodamp run: the loop never armed: " << s.arming.attempts
        << " attempt(s) within supervision.arm_deadline_s = " << s.arming.deadline_s
        << " s, last refusal: " << rt::to_string(s.arming.last_refusal) << '\n';
    return 5;
  }
  return 0;
}

}  // namespace robodamp::runtime
