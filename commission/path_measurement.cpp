#include "commission/path_measurement.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>

#include <spdlog/spdlog.h>

#include "commission/dwell_watch.hpp"
#include "commission/measurement_detail.hpp"
#include "config/robot_model_config.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;

// The running cell as the dwell watch sees it.
struct CellPort final : DwellCell {
  runtime::Cell* cell{nullptr};
  [[nodiscard]] std::vector<double> robot_pose_deg() const override { return cell->robot_pose_deg(); }
  [[nodiscard]] bool post(const rt::OperatorCommand& c) override { return cell->post(c); }
  void request_stop() noexcept override { cell->request_stop(); }
};

void check_options(const config::Config& cfg, const PathMeasureOptions& o) {
  const auto refuse = [&](const std::string& key, const std::string& why) {
    throw config::ConfigError({config::Problem{cfg.source, {}, key, why}});
  };
  if (!o.measure.pose_deg.empty()) refuse("--pose", "and --along-path: along the path the robot reports its pose");
  if (!cfg.pose_schedule)
    refuse("pose_schedule.model", "is missing: --along-path needs the robot model whose joints the robot reports");
  const bool registers = cfg.modbus && cfg.modbus->robot.joints_register >= 0;
  const bool topic = cfg.dds && cfg.dds->joint_states;
  if (!registers && !topic)
    refuse(cfg.modbus ? "modbus.robot.joints_register" : "modbus",
           "is missing: --along-path follows a robot that reports its joints (modbus.robot.joints_register or "
           "dds.joint_states); the simulated plant in process stands still (measure --poses measures it pose by pose)");
  if (o.dwells < 1) refuse("--dwells", "= " + std::to_string(o.dwells) + " (dwells) must be at least 1");
}

// The run's verdict: the watch's stop, the operator's abort, a trip, too few dwells, the recording's errors.
void judge(MeasureOutcome& out, const runtime::RunSummary& s, const DwellWatch& watch, const PathMeasureOptions& o,
           int measured) {
  if (watch.stopped()) {
    out.status = watch.stopped()->first, out.message = watch.stopped()->second;
  } else if (const int sig = rt::shutdown_signal().load(); sig != 0) {
    out.status = MeasureStatus::kAborted;
    out.message =
        "aborted by the operator (signal " + std::to_string(sig) + "): the dwells measured before it are kept";
  } else if (s.trip != "none") {
    out.status = MeasureStatus::kTripped;
    out.message =
        "the loop tripped (" + s.trip + " - " + s.trip_description + "): the dwells measured before it are kept";
  } else if (measured < o.dwells) {
    out.status = MeasureStatus::kIncomplete;
    out.message = std::to_string(measured) + " of " + std::to_string(o.dwells) + " dwells measured in the run's " +
                  std::to_string(static_cast<int>(o.max_run_s)) + " s (--duration): see each dwell's reason above";
  } else if (s.record_errors > 0) {
    out.status = MeasureStatus::kWriteError;
    out.message = "the recording had " + std::to_string(s.record_errors) + " write errors";
  }
}

// The dwell's measurement directory: its manifest (the chirp's place in the shared recording, the joints
// the robot reported), the recording linked in, the chirp's universal file without a hammer.
void write_dwell(const MeasureOutcome& run, DwellMeasurement& d, const std::string& out_dir, const config::Config& cfg,
                 bool impacts) {
  d.dir = fs::absolute(fs::path(out_dir) / d.name).lexically_normal().string();
  fs::create_directories(d.dir);
  const fs::path link = fs::path(d.dir) / identify::kRecordingName;
  std::error_code ec;
  fs::remove(link, ec);
  fs::create_hard_link(fs::path(out_dir) / identify::kRecordingName, link, ec);
  if (ec) fs::copy_file(fs::path(out_dir) / identify::kRecordingName, link, fs::copy_options::overwrite_existing);
  MeasureOutcome o = run;
  o.status = MeasureStatus::kOk, o.message.clear();
  identify::MeasurementManifest& m = o.manifest;
  const double shift_s = d.chirp_start_s - m.plan.chirp_start_s;
  m.plan.chirp_start_s += shift_s, m.plan.chirp_end_s += shift_s, m.plan.duration_s += shift_s;
  for (double& t : m.plan.impacts_start_s) t += shift_s;
  m.pose_deg = d.joints_deg, m.pose_name = d.name;
  m.robot_model = fs::absolute(cfg.pose_schedule->model_resolved).lexically_normal().string();
  m.run["dwell"] = {{"index", d.index},
                    {"still_s", d.still_s},
                    {"chirp_start_s", d.chirp_start_s},
                    {"chirp_end_s", d.chirp_end_s},
                    {"moved_s", d.moved_s}};
  detail::write_outputs(o, d.dir, false, !impacts);
  if (o.status != MeasureStatus::kOk) throw std::runtime_error(o.message);
}

void write_index(const std::string& out_dir, const std::string& config_path,
                 const std::vector<DwellMeasurement>& dwells) {
  nlohmann::json index = {{"format", "robodamp-pose-measurements"},
                          {"format_version", 1},
                          {"config_source", fs::absolute(config_path).lexically_normal().string()},
                          {"along_path", true},
                          {"poses", nlohmann::json::array()},
                          {"skipped", nlohmann::json::array()}};
  for (const auto& d : dwells) {
    if (d.measured)
      index["poses"].push_back(
          {{"name", d.name}, {"joints_deg", d.joints_deg}, {"dir", d.name}, {"status", 0}, {"message", ""}});
    else
      index["skipped"].push_back({{"name", d.name}, {"still_s", d.still_s}, {"reason", d.skipped}});
  }
  const fs::path path = fs::path(out_dir) / "poses.json";
  std::ofstream f(path);
  f << index.dump(2) << '\n';
  if (!f) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

int PathMeasureOutcome::measured() const { return measured_stops(dwells); }

// The run: configured, watched, run, judged, then one directory per measured stop.
PathMeasureOutcome measure_along_path(const config::Config& cfg, const std::string& config_path,
                                      const std::string& out_dir, const PathMeasureOptions& opt) {
  check_options(cfg, opt);
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan plan = detail::plan_for(cfg, model, opt.measure);
  fs::create_directories(out_dir);
  PathMeasureOutcome result;
  MeasureOutcome& out = result.run;
  const auto& c = cfg.commissioning;
  runtime::CellOptions o;
  if (!opt.measure.clock.empty())
    o.clock = opt.measure.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  o.record_path = (fs::path(out_dir) / identify::kRecordingName).string();
  o.pose_schedule_off = true, o.watch_joints = true;
  o.chirp = {true,          0.0,           c.chirp_period_s,       c.chirp_periods,
             c.chirp_f0_hz, c.chirp_f1_hz, plan.chirp_amplitude_v, 0.5 * c.chirp_period_s,
             true};
  detail::fill_manifest(out.manifest, config_path, cfg, model, plan);
  DwellWatch watch(cfg, plan, opt);
  CellPort port;
  o.on_frame = [&watch](const rt::TelemetryFrame& f) { watch.on_frame(f); };
  runtime::Cell cell(detail::running_config(cfg, opt.measure), o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    out.status = s.kind == runtime::StatusKind::kConfigError ? MeasureStatus::kConfigError : MeasureStatus::kFailed;
    out.message = s.message;
    return result;
  }
  port.cell = &cell;
  watch.attach(&port);
  out.manifest.backend = cell.hardware() ? "hardware" : "simulated plant";
  rt::install_shutdown_handlers();
  spdlog::info(
      "robodamp measure: along the path, {} dwells at most {} s: at each stop of the robot (its joints within {} deg "
      "for commissioning.settle_s = {} s) the chirp, {} periods of {} s at {:.3f} V, then the plant side's hammer "
      "until {:.1f} s after the stop",
      opt.dwells, opt.max_run_s, opt.still_deg, c.settle_s, c.chirp_periods, c.chirp_period_s, plan.chirp_amplitude_v,
      plan.duration_s);
  if (runtime::Status s = cell.activate(opt.max_run_s); !s.ok()) {
    out.status = MeasureStatus::kFailed;
    out.message = s.message;
    return result;
  }
  cell.wait();
  if (runtime::Status s = cell.deactivate(); !s.ok()) spdlog::warn("robodamp measure: {}", s.message);
  const runtime::RunSummary& s = cell.summary();
  out.final_state = s.final_state, out.trip = s.trip;
  out.saturated_ticks = s.supervisor.saturated_ticks, out.peak_command_v = s.peak_command_v;
  out.recorded_frames = s.recorded_frames;
  out.manifest.run = {{"final_state", s.final_state},
                      {"trip", s.trip},
                      {"saturated_ticks", s.supervisor.saturated_ticks},
                      {"peak_command_v", s.peak_command_v},
                      {"recorded_frames", s.recorded_frames},
                      {"record_errors", s.record_errors},
                      {"impacts", opt.measure.impacts},
                      {"control_on", opt.measure.control_on},
                      {"along_path", true},
                      {"gain_ns_per_m", opt.measure.control_on ? cfg.controller.gain_ns_per_m : 0.0}};
  result.dwells = watch.dwells();
  result.pauses = watch.pauses();
  judge(out, s, watch, opt, result.measured());
  try {
    for (auto& d : result.dwells)
      if (d.measured) write_dwell(out, d, out_dir, cfg, opt.measure.impacts);
    write_index(out_dir, config_path, result.dwells);
  } catch (const std::exception& e) {
    out.status = MeasureStatus::kWriteError;
    out.message = e.what();
  }
  return result;
}

}  // namespace robodamp::commission
