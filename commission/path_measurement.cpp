#include "commission/path_measurement.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>

#include <spdlog/spdlog.h>

#include "commission/measurement_detail.hpp"
#include "config/robot_model_config.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;

constexpr double kPosePollS = 0.01;     // loop time between two readings of the joints
constexpr double kStillWindowS = 0.25;  // the joints unchanged this long: the robot stopped (polls, register steps)
constexpr double kRestWindowS = 1.0;    // the rest check's window before a chirp (as a stopped measurement's)

int measured_stops(const std::vector<DwellMeasurement>& dwells) {
  return static_cast<int>(std::count_if(dwells.begin(), dwells.end(), [](const auto& d) { return d.measured; }));
}

// Finds the robot's stops from the joints it reports, starts the chirp at each, watches it (on the drain
// thread, one call per frame), and stops the run once enough dwells are measured or the chirp saturates.
class DwellWatch {
 public:
  DwellWatch(const config::Config& cfg, const analysis::CommissioningPlan& plan, const PathMeasureOptions& o)
      : plan_(plan),
        o_(o),
        settle_s_(cfg.commissioning.settle_s),
        rest_limit_(cfg.commissioning.rest_accel_rms_mps2),
        chirp_s_(cfg.commissioning.chirp_period_s * cfg.commissioning.chirp_periods),
        fs_hz_(cfg.loop.rate_hz),
        rest_sq_(static_cast<std::size_t>(std::lround(kRestWindowS * cfg.loop.rate_hz)), 0.0) {}
  void attach(runtime::Cell* cell) { cell_ = cell; }
  [[nodiscard]] const std::optional<std::pair<MeasureStatus, std::string>>& stopped() const { return stopped_; }
  [[nodiscard]] const std::vector<DwellMeasurement>& dwells() const { return dwells_; }

  void on_frame(const rt::TelemetryFrame& f) {
    watch_rest(f);
    watch_chirp(f);
    if (f.time_s < next_poll_s_ || cell_ == nullptr) return;
    next_poll_s_ = f.time_s + kPosePollS;
    const std::vector<double> q = cell_->robot_pose_deg();
    if (moved(q)) {
      on_move(f.time_s);
      ref_ = q, still_since_s_ = f.time_s;
      return;
    }
    step(f);
  }

 private:
  enum class Phase { kMoving, kStill, kStartPosted, kChirping, kHolding, kDone };

  void stop(MeasureStatus s, std::string why) {
    if (stopped_) return;
    stopped_.emplace(s, std::move(why));
    spdlog::warn("robodamp measure: {}", stopped_->second);
    cell_->request_stop();
  }
  void watch_rest(const rt::TelemetryFrame& f) {
    const double a = std::isfinite(f.accel_mps2) ? f.accel_mps2 : 0.0;
    rest_sum_ += a * a - rest_sq_[rest_at_];
    rest_sq_[rest_at_] = a * a;
    rest_at_ = (rest_at_ + 1) % rest_sq_.size();
    rest_n_ = std::min(rest_n_ + 1, rest_sq_.size());
  }
  [[nodiscard]] double rest_rms_mps2() const {
    return rest_n_ == 0 ? 0.0 : std::sqrt(std::max(0.0, rest_sum_) / static_cast<double>(rest_n_));
  }
  void watch_chirp(const rt::TelemetryFrame& f) {
    if (phase_ == Phase::kStartPosted &&
        static_cast<rt::CommandKind>(f.command_kind) == rt::CommandKind::kStartExcitation) {
      DwellMeasurement& d = dwells_.back();
      d.chirp_start_s = static_cast<double>(f.tick + 1) / fs_hz_;  // the chirp's first sample is the next tick's
      d.chirp_end_s = d.chirp_start_s + chirp_s_;
      phase_ = Phase::kChirping;
      saturated0_ = f.saturated_ticks;
      spdlog::info("robodamp measure: dwell {} at {}: the chirp from {:.2f} s to {:.2f} s", d.index,
                   config::describe_pose(ref_), d.chirp_start_s, d.chirp_end_s);
    }
    if (phase_ == Phase::kChirping && f.saturated_ticks > saturated0_) {
      char b[256];
      std::snprintf(b, sizeof b,
                    "the excitation saturates at dwell %d: the supervisor limited the command at %.3f s "
                    "(%.3f V): the measurement would not be linear; stopped. Lower commissioning.chirp_force_fraction",
                    dwells_.back().index, f.time_s, f.command_v);
      stop(MeasureStatus::kSaturated, b);
    }
  }
  [[nodiscard]] bool moved(const std::vector<double>& q) const {
    if (q.empty() || q.size() != ref_.size()) return true;  // not known yet (or lost): not standing anywhere
    for (std::size_t i = 0; i < q.size(); ++i)
      if (std::abs(q[i] - ref_[i]) > o_.still_deg) return true;
    return false;
  }
  void skip(const std::string& why) {
    dwells_.back().skipped = why;
    spdlog::warn("robodamp measure: dwell {} not measured: {}", dwells_.back().index, why);
  }
  void on_move(double t_s) {
    if (phase_ == Phase::kMoving) return;
    DwellMeasurement& d = dwells_.back();
    d.moved_s = t_s;
    char b[200];
    if (phase_ == Phase::kStill || phase_ == Phase::kStartPosted) {
      std::snprintf(b, sizeof b,
                    "the robot moved %.2f s after it stopped, before the chirp (it needs commissioning.settle_s "
                    "= %g s of stillness)",
                    t_s - d.still_s, settle_s_);
      skip(b);
    } else if (phase_ == Phase::kChirping) {
      std::snprintf(b, sizeof b, "the robot moved at %.2f s, during the chirp (%.2f-%.2f s)", t_s, d.chirp_start_s,
                    d.chirp_end_s);
      d.measured = false;
      skip(b);
    } else if (phase_ == Phase::kHolding) {
      spdlog::warn(
          "robodamp measure: dwell {}: the robot left at {:.2f} s, {:.2f} s before the hammer's window ended: the "
          "plant side's impacts there may be incomplete",
          d.index, t_s, d.still_s + plan_.duration_s - t_s);
    }
    phase_ = Phase::kMoving;
  }
  void step(const rt::TelemetryFrame& f) {
    const double t = f.time_s;
    switch (phase_) {
      case Phase::kMoving:
        if (t - still_since_s_ < kStillWindowS) return;
        dwells_.push_back({});
        dwells_.back().index = static_cast<int>(dwells_.size());
        dwells_.back().name = "dwell_" + std::to_string(dwells_.size());
        dwells_.back().still_s = still_since_s_;
        spdlog::info("robodamp measure: dwell {}: the robot stands at {} since {:.2f} s", dwells_.size(),
                     config::describe_pose(ref_), still_since_s_);
        phase_ = Phase::kStill;
        return;
      case Phase::kStill:
        return start_chirp(f);
      case Phase::kStartPosted:
        return;
      case Phase::kChirping:
        accumulate_pose();
        if (t < dwells_.back().chirp_end_s) return;
        dwells_.back().measured = true;
        phase_ = Phase::kHolding;
        return;
      case Phase::kHolding:
        if (t < dwells_.back().still_s + plan_.duration_s)
          return;  // the plant side's hammer, on a stopped plan's times
        phase_ = Phase::kDone;
        if (measured_stops(dwells_) >= o_.dwells) cell_->request_stop();
        return;
      case Phase::kDone:
        return;
    }
  }
  void start_chirp(const rt::TelemetryFrame& f) {
    if (f.time_s < still_since_s_ + settle_s_) return;
    char b[256];
    if (static_cast<rt::State>(f.state) != rt::State::kActive) {
      std::snprintf(b, sizeof b,
                    "the loop is %s when the chirp is due at %.2f s (the amplifier ready and a fresh sensor are "
                    "needed)",
                    rt::to_string(static_cast<rt::State>(f.state)), f.time_s);
      skip(b);
      phase_ = Phase::kDone;
    } else if (rest_rms_mps2() > rest_limit_) {
      std::snprintf(b, sizeof b,
                    "the cell is not at rest when the chirp is due, %.3f m/s^2 RMS over the last second "
                    "(commissioning.rest_accel_rms_mps2 = %g)",
                    rest_rms_mps2(), rest_limit_);
      skip(b);
      phase_ = Phase::kDone;
    } else if (cell_->post({rt::CommandKind::kStartExcitation, 0.0})) {
      phase_ = Phase::kStartPosted;
    }  // a full command queue: again at the next reading of the joints
  }
  void accumulate_pose() {
    DwellMeasurement& d = dwells_.back();
    if (d.joints_deg.empty()) d.joints_deg.assign(ref_.size(), 0.0), pose_n_ = 0;
    const std::vector<double> q = cell_->robot_pose_deg();
    if (q.size() != d.joints_deg.size()) return;
    ++pose_n_;
    for (std::size_t i = 0; i < q.size(); ++i)
      d.joints_deg[i] += (q[i] - d.joints_deg[i]) / static_cast<double>(pose_n_);
  }

  analysis::CommissioningPlan plan_;
  PathMeasureOptions o_;
  double settle_s_, rest_limit_, chirp_s_, fs_hz_;
  runtime::Cell* cell_{nullptr};
  std::optional<std::pair<MeasureStatus, std::string>> stopped_;
  std::vector<DwellMeasurement> dwells_;
  Phase phase_{Phase::kMoving};
  std::vector<double> ref_;
  double still_since_s_{0.0}, next_poll_s_{0.0};
  std::uint32_t saturated0_{0};
  std::vector<double> rest_sq_;
  std::size_t rest_at_{0}, rest_n_{0}, pose_n_{0};
  double rest_sum_{0.0};
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
  o.on_frame = [&watch](const rt::TelemetryFrame& f) { watch.on_frame(f); };
  runtime::Cell cell(detail::running_config(cfg, opt.measure), o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    out.status = s.kind == runtime::StatusKind::kConfigError ? MeasureStatus::kConfigError : MeasureStatus::kFailed;
    out.message = s.message;
    return result;
  }
  watch.attach(&cell);
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
