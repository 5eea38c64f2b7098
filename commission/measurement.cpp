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
#include "commission/modal_test_hook.hpp"
#include "config/robot_model_config.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;

// One progress line per phase of the plan, from the drained frames' loop time.
class Progress {
 public:
  Progress(const analysis::CommissioningPlan& p, const std::vector<std::pair<int, std::string>>& locations,
           double chirp_period_s)
      : plan_(p), locations_(locations), period_s_(chirp_period_s) {}
  void on_frame(const rt::TelemetryFrame& f) {
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
  int last_{-1};
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
    return "--pose " + pose + ": " + cfg.source + " has no pose_schedule.model, the robot model whose joints the pose names";
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  if (auto p = config::pose_problem(model, opt.pose_deg)) return "--pose " + pose + ": " + *p;
  o.pose_deg = opt.pose_deg;
  o.pose_schedule_off = true;
  m.pose_deg = opt.pose_deg;
  m.pose_name = opt.pose_name;
  m.robot_model = fs::absolute(cfg.pose_schedule->model_resolved).lexically_normal().string();
  return std::nullopt;
}

}  // namespace

int exit_code(MeasureStatus s) {
  switch (s) {
    case MeasureStatus::kOk: return 0;
    case MeasureStatus::kConfigError: return 2;
    case MeasureStatus::kTripped: return 4;
    case MeasureStatus::kIncomplete: return 5;
    case MeasureStatus::kFailed:
    case MeasureStatus::kWriteError: return 1;
  }
  return 1;
}

// long: the measurement's sequence on a cell (configure, hook, run, write), one rollback path; left for a later pass
MeasureOutcome measure(const std::string& config_path, const std::string& out_dir, const MeasureOptions& opt) {
  const config::Config cfg = config::load_config_file(config_path);
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan plan = analysis::commissioning_plan(cfg, model);
  fs::create_directories(out_dir);
  MeasureOutcome out;

  config::Config off = cfg;  // control off: the loop runs, the controller's gain is 0
  off.controller.gain_ns_per_m = 0.0;
  if (off.pose_schedule)  // each region's set carries its own gain: off as well, or the loop damps what it measures
    for (auto& r : off.pose_schedule->regions) r.gain_ns_per_m = 0.0;
  const auto& c = cfg.commissioning;
  runtime::CellOptions o;
  if (!opt.clock.empty()) o.clock = opt.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  else if (!cfg.can) o.clock = config::ClockKind::kVirtual;  // the simulated plant: nothing to pace
  o.record_path = (fs::path(out_dir) / identify::kRecordingName).string();
  o.keep_frames = true;
  if (const auto refused = apply_pose(cfg, opt, o, out.manifest)) {
    out.status = MeasureStatus::kConfigError;
    out.message = *refused;
    return out;
  }
  o.chirp = {true, plan.chirp_start_s, c.chirp_period_s, c.chirp_periods, c.chirp_f0_hz, c.chirp_f1_hz,
             plan.chirp_amplitude_v};
  identify::MeasurementManifest& m = out.manifest;
  m.config_source = fs::absolute(config_path).lexically_normal().string();
  m.config_text = cfg.yaml_text;
  m.loop_rate_hz = cfg.loop.rate_hz;
  m.plan = plan;
  for (const auto& l : cfg.robot.locations) m.locations.emplace_back(l.id, l.name);
  m.sensor_location_id = cfg.sensor.location;
  m.actuator_location_id = model.locations[model.actuator.location].id;
  Progress progress(plan, m.locations, c.chirp_period_s);
  o.on_frame = [&progress](const rt::TelemetryFrame& f) { progress.on_frame(f); };

  runtime::Cell cell(off, o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    out.status = s.kind == runtime::StatusKind::kConfigError ? MeasureStatus::kConfigError : MeasureStatus::kFailed;
    out.message = s.message;
    return out;
  }
  m.backend = cell.hardware() ? "hardware" : "simulated plant";
  std::unique_ptr<analysis::ModalTest> test;
  std::unique_ptr<ModalTestHook> hook;
  if (!cell.hardware()) {
    test = std::make_unique<analysis::ModalTest>(cfg, cell.plant(), plan);
    hook = std::make_unique<ModalTestHook>(*test);
    cell.sim_backend().set_step_hook(hook.get());
  }
  rt::install_shutdown_handlers();
  spdlog::info("robodamp measure: {} on {}, {:.0f} s: control off, chirp {:.1f}-{:.1f} Hz at {:.3f} V from {:.1f} s "
               "(predicted peak actuator force {:.1f} N of {:.0f} N), then {} impacts of {:.0f} N at each of {} locations",
               config_path, m.backend, plan.duration_s, c.chirp_f0_hz, c.chirp_f1_hz, plan.chirp_amplitude_v,
               plan.chirp_start_s, plan.predicted_peak_force_n, cfg.actuator.force_limit_n, c.impacts_per_location,
               cfg.bench.impact_peak_n, m.locations.size());
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
  m.run = {{"final_state", s.final_state}, {"trip", s.trip}, {"saturated_ticks", s.supervisor.saturated_ticks},
           {"peak_command_v", s.peak_command_v}, {"chirp_active_share", out.chirp_active_share},
           {"recorded_frames", s.recorded_frames}, {"record_errors", s.record_errors}};
  if (test) {
    out.frf_files = test->write_frf_csvs(out_dir).size();
    out.impact_records = test->records();
    out.impact_records_planned = test->records_planned();
    m.run["impact_records"] = test->records();
  }
  {
    std::ofstream f(fs::path(out_dir) / identify::kManifestName);
    f << identify::to_json(m).dump(2) << '\n';
    if (!f) {
      out.status = MeasureStatus::kWriteError;
      out.message = "cannot write " + (fs::path(out_dir) / identify::kManifestName).string();
      return out;
    }
  }
  if (s.trip != "none") {
    out.status = MeasureStatus::kTripped;
    out.message = "the loop tripped (" + s.trip + " - " + s.trip_description + "): the measurement is incomplete";
  } else if (out.chirp_active_share < 1.0) {
    out.status = MeasureStatus::kIncomplete;
    out.message = "the loop was not active for the whole chirp (" + std::to_string(100.0 * out.chirp_active_share) +
                  " % of its ticks): raise commissioning.settle_s or look at the arming refusals";
  } else if (s.record_errors > 0) {
    out.status = MeasureStatus::kWriteError;
    out.message = "the recording had " + std::to_string(s.record_errors) + " write errors";
  } else if (test) {
    // The measurement as a universal file for a modal package (with hardware the plant side writes the
    // impact FRFs later: identify all and commission export them).
    const std::string uff = (fs::path(out_dir) / identify::kMeasurementUffName).string();
    try {
      measfiles::write_uff(uff, identify::measurement_to_uff(identify::read_measurement_dir(out_dir)), measfiles::UffEncoding::kAscii);
    } catch (const std::exception& e) {
      out.status = MeasureStatus::kWriteError;
      out.message = uff + ": " + e.what();
    }
  }
  return out;
}

}  // namespace robodamp::commission
