#include "commission/measurement.hpp"

#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>

#include "analysis/modal_test.hpp"
#include "commission/measurement_detail.hpp"
#include "commission/modal_test_hook.hpp"
#include "config/robot_model_config.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;

// One progress line per phase of the plan, from the drained frames' loop time; and the run's safety
// watch: not ready or not at rest when the chirp is due, a limited tick during the chirp: the cell stops
// at once (on the drain thread, a few ticks later) with the reason.
class Progress {
 public:
  Progress(const analysis::CommissioningPlan& p, const std::vector<std::pair<int, std::string>>& locations,
           const config::CommissioningConfig& c)
      : plan_(p),
        locations_(locations),
        period_s_(c.chirp_period_s),
        rest_limit_(c.rest_accel_rms_mps2),
        f0_hz_(c.chirp_f0_hz),
        f1_hz_(c.chirp_f1_hz) {}
  void attach(runtime::Cell* cell) { cell_ = cell; }
  [[nodiscard]] const std::optional<std::pair<MeasureStatus, std::string>>& stopped() const { return stopped_; }
  [[nodiscard]] double rest_rms_mps2() const {
    return rest_n_ == 0 ? 0.0 : std::sqrt(rest_sum_sq_ / static_cast<double>(rest_n_));
  }
  void on_frame(const rt::TelemetryFrame& f) {
    watch(f);
    log_phase(f);
  }

 private:
  void stop(MeasureStatus s, std::string why) {
    if (stopped_) return;
    stopped_.emplace(s, std::move(why));
    spdlog::warn("robodamp measure: {}", stopped_->second);
    if (cell_ != nullptr) cell_->request_stop();
  }
  void watch(const rt::TelemetryFrame& f) {
    if (f.time_s >= plan_.chirp_start_s - 1.0 && f.time_s < plan_.chirp_start_s && std::isfinite(f.accel_mps2))
      rest_sum_sq_ += f.accel_mps2 * f.accel_mps2, ++rest_n_;
    if (f.time_s < plan_.chirp_start_s || f.time_s >= plan_.chirp_end_s) return;
    if (!started_) {
      started_ = true;
      sat0_ = f.saturated_ticks;
      const auto state = static_cast<rt::State>(f.state);
      char b[256];
      if (state != rt::State::kActive) {
        const auto trip = static_cast<rt::Trip>(f.trip);
        std::snprintf(b, sizeof b,
                      "not ready: the loop is %s%s%s when the chirp is due at %.1f s (the amplifier ready, a "
                      "fresh sensor and the robot's state are needed)",
                      rt::to_string(state), trip == rt::Trip::kNone ? "" : ", tripped ",
                      trip == rt::Trip::kNone ? "" : rt::to_string(trip), plan_.chirp_start_s);
        stop(MeasureStatus::kNotReady, b);
      } else if (rest_rms_mps2() > rest_limit_) {
        std::snprintf(b, sizeof b,
                      "not ready: the cell is not at rest, %.3f m/s^2 RMS at the sensor over the second before the "
                      "chirp (commissioning.rest_accel_rms_mps2 = %g): a moving robot, a turning spindle or a cut",
                      rest_rms_mps2(), rest_limit_);
        stop(MeasureStatus::kNotReady, b);
      }
      return;
    }
    if (f.saturated_ticks > sat0_) {
      const double tau = std::fmod(f.time_s - plan_.chirp_start_s, period_s_);
      const double f_hz = f0_hz_ + (f1_hz_ - f0_hz_) * tau / period_s_;
      char b[320];
      std::snprintf(
          b, sizeof b,
          "the excitation saturates: the supervisor limited the command at %.3f s (the chirp near %.1f Hz, "
          "%.3f V): the measurement would not be linear; stopped. Lower commissioning.chirp_force_fraction (the "
          "chirp's level) or, with control on, the gain",
          f.time_s, f_hz, f.command_v);
      stop(MeasureStatus::kSaturated, b);
    }
  }
  void log_phase(const rt::TelemetryFrame& f) {
    const int phase = phase_at(f.time_s);
    if (phase == last_) return;
    last_ = phase;
    const auto n_chirp = static_cast<std::size_t>(std::lround((plan_.chirp_end_s - plan_.chirp_start_s) / period_s_));
    if (phase == 0) return;
    if (phase <= static_cast<int>(n_chirp)) {
      spdlog::info("robodamp measure: {:.1f} s chirp period {} of {} ({}), state {}", f.time_s, phase, n_chirp,
                   phase == 1 ? "transient, discarded" : "averaged", rt::to_string(static_cast<rt::State>(f.state)));
    } else if (phase <= static_cast<int>(n_chirp + locations_.size())) {
      const auto& l = locations_[static_cast<std::size_t>(phase) - n_chirp - 1];
      spdlog::info("robodamp measure: {:.1f} s impacts at the {} (location {})", f.time_s, l.second, l.first);
    }
  }

 private:
  int phase_at(double t) const {
    if (t < plan_.chirp_start_s) return 0;
    if (t < plan_.chirp_end_s) return 1 + static_cast<int>((t - plan_.chirp_start_s) / period_s_);
    const int chirp = static_cast<int>(std::lround((plan_.chirp_end_s - plan_.chirp_start_s) / period_s_));
    int k = 0;
    for (std::size_t i = 0; i < plan_.impacts_start_s.size(); ++i)
      if (t >= plan_.impacts_start_s[i]) k = static_cast<int>(i) + 1;
    return k == 0 ? chirp + 100 : chirp + k;  // the quiet gap: no line
  }
  analysis::CommissioningPlan plan_;
  std::vector<std::pair<int, std::string>> locations_;
  double period_s_;
  double rest_limit_;
  int last_{-1};
  runtime::Cell* cell_{nullptr};
  std::optional<std::pair<MeasureStatus, std::string>> stopped_;
  bool started_{false};
  std::uint32_t sat0_{0};
  double rest_sum_sq_{0.0};
  std::size_t rest_n_{0};
  double f0_hz_, f1_hz_;
};

// The share of the chirp's ticks with the loop active (the test signal only plays there).
double chirp_active_share(const std::vector<rt::TelemetryFrame>& frames, const analysis::CommissioningPlan& p) {
  std::size_t in = 0, active = 0;
  for (const auto& f : frames) {
    if (f.time_s < p.chirp_start_s || f.time_s >= p.chirp_end_s) continue;
    ++in;
    if (f.state == static_cast<std::uint8_t>(rt::State::kActive)) ++active;
  }
  return in == 0 ? 0.0 : static_cast<double>(active) / static_cast<double>(in);
}

// --pose: the joints against the configuration's robot model (count, travel); the cell stands there with
// the pose schedule off (the gain is 0: no set to choose, and a pose outside the scheduled workspace is
// worth measuring). The problem, if the pose is refused.
std::optional<std::string> apply_pose(const config::Config& cfg, const MeasureOptions& opt, runtime::CellOptions& o,
                                      identify::MeasurementManifest& m) {
  if (opt.pose_deg.empty()) return std::nullopt;
  const std::string pose = config::describe_pose(opt.pose_deg);
  if (!cfg.pose_schedule)
    return "--pose " + pose + ": " + cfg.source +
           " has no pose_schedule.model, the robot model whose joints the pose names";
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  if (auto p = config::pose_problem(model, opt.pose_deg)) return "--pose " + pose + ": " + *p;
  o.pose_deg = opt.pose_deg;
  o.pose_schedule_off = true;
  m.pose_deg = opt.pose_deg;
  m.pose_name = opt.pose_name;
  m.robot_model = fs::absolute(cfg.pose_schedule->model_resolved).lexically_normal().string();
  return std::nullopt;
}

// The run's verdict, in order: the watch's stop, the operator's abort, a trip, an incomplete chirp, the
// recording's errors.
void judge(MeasureOutcome& out, const runtime::RunSummary& s, const Progress& watch) {
  if (watch.stopped()) {
    out.status = watch.stopped()->first;
    out.message = watch.stopped()->second;
  } else if (const int sig = rt::shutdown_signal().load(); sig != 0) {
    out.status = MeasureStatus::kAborted;
    out.message = "aborted by the operator (signal " + std::to_string(sig) +
                  "): the command ramped to 0 through the "
                  "safe state; the measurement is incomplete";
  } else if (s.trip != "none") {
    out.status = MeasureStatus::kTripped;
    out.message = "the loop tripped (" + s.trip + " - " + s.trip_description + "): the measurement is incomplete";
  } else if (out.chirp_active_share < 1.0) {
    out.status = MeasureStatus::kIncomplete;
    out.message = "the loop was not active for the whole chirp (" + std::to_string(100.0 * out.chirp_active_share) +
                  " % of its ticks): raise commissioning.settle_s or look at the arming refusals";
  } else if (s.record_errors > 0) {
    out.status = MeasureStatus::kWriteError;
    out.message = "the recording had " + std::to_string(s.record_errors) + " write errors";
  }
}

}  // namespace

namespace detail {

// The plan of a run with these options: without impacts the run ends a second after the chirp.
analysis::CommissioningPlan plan_for(const config::Config& cfg, const sim::PlantModel& model, const MeasureOptions& o) {
  analysis::CommissioningPlan plan = analysis::commissioning_plan(cfg, model);
  if (!o.impacts) {
    plan.impacts_start_s.clear();
    plan.duration_s = plan.chirp_end_s + 1.0;
  }
  return plan;
}

// The configuration the loop runs: control off (every set's gain 0) unless the chirp verifies the controller.
config::Config running_config(const config::Config& cfg, const MeasureOptions& o) {
  config::Config c = cfg;
  if (o.control_on) return c;
  c.controller.gain_ns_per_m = 0.0;
  if (c.pose_schedule)  // each region's set carries its own gain: off as well, or the loop damps what it measures
    for (auto& r : c.pose_schedule->regions) r.gain_ns_per_m = 0.0;
  return c;
}

void fill_manifest(identify::MeasurementManifest& m, const std::string& config_path, const config::Config& cfg,
                   const sim::PlantModel& model, const analysis::CommissioningPlan& plan) {
  m.config_source = fs::absolute(config_path).lexically_normal().string();
  m.config_text = cfg.yaml_text;
  m.loop_rate_hz = cfg.loop.rate_hz;
  m.plan = plan;
  for (const auto& l : cfg.robot.locations) m.locations.emplace_back(l.id, l.name);
  m.sensor_location_id = cfg.sensor.location;
  m.actuator_location_id = model.locations[model.actuator.location].id;
}

// measurement.json (with the refusal, if any), and the measurement as a universal file for a modal
// package: with the impacts measured here all of it; with the chirp alone (a real cell) the actuator's
// FRF at the sensor with its coherence; with hardware's impacts the plant side writes their FRFs later
// (identify all and commission export them).
void write_outputs(MeasureOutcome& out, const std::string& out_dir, bool impacts_here, bool chirp_only) {
  identify::MeasurementManifest& m = out.manifest;
  if (out.status != MeasureStatus::kOk) m.run["refused"] = out.message;
  {
    std::ofstream f(fs::path(out_dir) / identify::kManifestName);
    f << identify::to_json(m).dump(2) << '\n';
    if (!f) {
      out.status = MeasureStatus::kWriteError;
      out.message = "cannot write " + (fs::path(out_dir) / identify::kManifestName).string();
      return;
    }
  }
  if (out.status != MeasureStatus::kOk || !(impacts_here || chirp_only)) return;
  const std::string uff = (fs::path(out_dir) / identify::kMeasurementUffName).string();
  try {
    identify::CommissioningInputs in;
    if (impacts_here) {
      in = identify::read_measurement_dir(out_dir);
    } else {
      in.manifest = m;
      in.chirp = identify::read_chirp_measurement((fs::path(out_dir) / identify::kRecordingName).string(),
                                                  m.config_source, m.plan.chirp_start_s);
    }
    measfiles::write_uff(uff, identify::measurement_to_uff(in), measfiles::UffEncoding::kAscii);
  } catch (const std::exception& e) {
    out.status = MeasureStatus::kWriteError;
    out.message = uff + ": " + e.what();
  }
}

}  // namespace detail

int exit_code(MeasureStatus s) {
  switch (s) {
    case MeasureStatus::kOk:
      return 0;
    case MeasureStatus::kConfigError:
      return 2;
    case MeasureStatus::kTripped:
      return 4;
    case MeasureStatus::kIncomplete:
      return 5;
    case MeasureStatus::kNotReady:
      return 6;
    case MeasureStatus::kSaturated:
      return 7;
    case MeasureStatus::kAborted:
      return 8;
    case MeasureStatus::kFailed:
    case MeasureStatus::kWriteError:
      return 1;
  }
  return 1;
}

std::string measurement_plan(const std::string& config_path, const MeasureOptions& o) {
  return measurement_plan(config::load_config_file(config_path), config_path, o);
}

std::string measurement_plan(const config::Config& cfg, const std::string& config_path, const MeasureOptions& o) {
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan p = detail::plan_for(cfg, model, o);
  const auto& c = cfg.commissioning;
  char b[1024];
  std::string t = "robodamp measure plan for " + config_path + " (" +
                  (cfg.can ? "the cell behind " + cfg.can->interface : std::string("the simulated plant")) + "):\n";
  std::snprintf(
      b, sizeof b,
      "  0.0 - %.1f s   the loop arms, control %s (K = %.0f N s/m); the chirp waits until the loop is active "
      "(amplifier ready, sensor fresh, robot state known) and the cell at rest (< %g m/s^2 RMS at the sensor)\n",
      p.chirp_start_s, o.control_on ? "ON" : "off", o.control_on ? cfg.controller.gain_ns_per_m : 0.0,
      c.rest_accel_rms_mps2);
  t += b;
  std::snprintf(
      b, sizeof b,
      "  %.1f - %.1f s  what moves: the inertial actuator's mass only; %d periods of a %.1f-%.1f Hz chirp, %.1f s "
      "each, "
      "at %.3f V (%.0f %% of the amplifier's %.1f V), ramped up over the first %.1f s; predicted peak actuator force "
      "%.1f N of its %.0f N limit\n",
      p.chirp_start_s, p.chirp_end_s, c.chirp_periods, c.chirp_f0_hz, c.chirp_f1_hz, c.chirp_period_s,
      p.chirp_amplitude_v, 100.0 * p.chirp_amplitude_v / cfg.amplifier.voltage_limit_v, cfg.amplifier.voltage_limit_v,
      0.5 * c.chirp_period_s, p.predicted_peak_force_n, cfg.actuator.force_limit_n);
  t += b;
  if (o.impacts) {
    std::snprintf(b, sizeof b,
                  "  %.1f - %.1f s  hammer impacts of %.0f N, %d at each of %zu locations (the plant side's hammer)\n",
                  p.impacts_start_s.empty() ? p.chirp_end_s : p.impacts_start_s.front(), p.duration_s - 1.0,
                  cfg.bench.impact_peak_n, c.impacts_per_location, model.locations.size());
    t += b;
  } else {
    t += "  no hammer: the tool tip's FRFs come from your tap tests (commission --tap-tests)\n";
  }
  std::snprintf(b, sizeof b, "  %.1f s in all. The robot must stand still and the spindle be stopped throughout.\n",
                p.duration_s);
  t += b;
  t += "  It stops at once, through the safe state, on Ctrl-C (SIGINT) or SIGTERM, on any trip, when the loop is not "
       "ready "
       "or the cell not at rest when the chirp is due, and when the supervisor limits a command during the chirp.\n";
  return t;
}

MeasureOutcome measure(const std::string& config_path, const std::string& out_dir, const MeasureOptions& opt) {
  return measure(config::load_config_file(config_path), config_path, out_dir, opt);
}

// long: the measurement's sequence on a cell (configure, hook, run, judge), one rollback path
MeasureOutcome measure(const config::Config& cfg, const std::string& config_path, const std::string& out_dir,
                       const MeasureOptions& opt) {
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan plan = detail::plan_for(cfg, model, opt);
  fs::create_directories(out_dir);
  MeasureOutcome out;
  const auto& c = cfg.commissioning;
  runtime::CellOptions o;
  if (!opt.clock.empty())
    o.clock = opt.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  else if (!cfg.can)
    o.clock = config::ClockKind::kVirtual;  // the simulated plant: nothing to pace
  o.record_path = (fs::path(out_dir) / identify::kRecordingName).string();
  o.keep_frames = true;
  if (const auto refused = apply_pose(cfg, opt, o, out.manifest)) {
    out.status = MeasureStatus::kConfigError;
    out.message = *refused;
    return out;
  }
  o.chirp = {true,          plan.chirp_start_s, c.chirp_period_s,       c.chirp_periods,
             c.chirp_f0_hz, c.chirp_f1_hz,      plan.chirp_amplitude_v, 0.5 * c.chirp_period_s};
  identify::MeasurementManifest& m = out.manifest;
  detail::fill_manifest(m, config_path, cfg, model, plan);
  Progress progress(plan, m.locations, c);
  o.on_frame = [&progress](const rt::TelemetryFrame& f) { progress.on_frame(f); };

  runtime::Cell cell(detail::running_config(cfg, opt), o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    out.status = s.kind == runtime::StatusKind::kConfigError ? MeasureStatus::kConfigError : MeasureStatus::kFailed;
    out.message = s.message;
    return out;
  }
  progress.attach(&cell);
  m.backend = cell.hardware() ? "hardware" : "simulated plant";
  std::unique_ptr<analysis::ModalTest> test;
  std::unique_ptr<ModalTestHook> hook;
  if (!cell.hardware() && opt.impacts) {
    test = std::make_unique<analysis::ModalTest>(cfg, cell.plant(), plan);
    hook = std::make_unique<ModalTestHook>(*test);
    cell.sim_backend().set_step_hook(hook.get());
  }
  rt::install_shutdown_handlers();
  spdlog::info("{}", measurement_plan(cfg, config_path, opt));
  if (runtime::Status s = cell.activate(plan.duration_s); !s.ok()) {
    out.status = MeasureStatus::kFailed;
    out.message = s.message;
    return out;
  }
  cell.wait();
  if (runtime::Status s = cell.deactivate(); !s.ok()) spdlog::warn("robodamp measure: {}", s.message);
  const runtime::RunSummary& s = cell.summary();
  out.chirp_active_share = chirp_active_share(cell.frames(), plan);
  out.final_state = s.final_state;
  out.trip = s.trip;
  out.saturated_ticks = s.supervisor.saturated_ticks;
  out.peak_command_v = s.peak_command_v;
  out.recorded_frames = s.recorded_frames;
  out.rest_accel_rms_mps2 = progress.rest_rms_mps2();
  m.run = {{"final_state", s.final_state},
           {"trip", s.trip},
           {"saturated_ticks", s.supervisor.saturated_ticks},
           {"peak_command_v", s.peak_command_v},
           {"chirp_active_share", out.chirp_active_share},
           {"recorded_frames", s.recorded_frames},
           {"record_errors", s.record_errors},
           {"impacts", opt.impacts},
           {"control_on", opt.control_on},
           {"gain_ns_per_m", opt.control_on ? cfg.controller.gain_ns_per_m : 0.0},
           {"rest_accel_rms_mps2", out.rest_accel_rms_mps2}};
  if (test) {
    out.frf_files = test->write_frf_csvs(out_dir).size();
    out.impact_records = test->records();
    out.impact_records_planned = test->records_planned();
    m.run["impact_records"] = test->records();
  }
  judge(out, s, progress);
  detail::write_outputs(out, out_dir, test != nullptr, !opt.impacts);
  return out;
}

}  // namespace robodamp::commission
