// The robot's stops from the joints it reports (commission/dwell_watch.hpp).
#include "commission/dwell_watch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <spdlog/spdlog.h>

#include "config/robot_model_config.hpp"

namespace robodamp::commission {

namespace {

constexpr double kPosePollS = 0.01;     // loop time between two readings of the joints
constexpr double kStillWindowS = 0.25;  // the joints unchanged this long: the robot stopped (polls, register steps)
constexpr double kRestWindowS = 1.0;    // the rest check's window before a chirp (as a stopped measurement's)

}  // namespace

int measured_stops(const std::vector<DwellMeasurement>& dwells) {
  return static_cast<int>(std::count_if(dwells.begin(), dwells.end(), [](const auto& d) { return d.measured; }));
}

DwellWatch::DwellWatch(const config::Config& cfg, const analysis::CommissioningPlan& plan, const PathMeasureOptions& o)
    : plan_(plan),
      o_(o),
      settle_s_(cfg.commissioning.settle_s),
      rest_limit_(cfg.commissioning.rest_accel_rms_mps2),
      chirp_s_(cfg.commissioning.chirp_period_s * cfg.commissioning.chirp_periods),
      fs_hz_(cfg.loop.rate_hz),
      rest_sq_(static_cast<std::size_t>(std::lround(kRestWindowS * cfg.loop.rate_hz)), 0.0) {}

void DwellWatch::on_frame(const rt::TelemetryFrame& f) {
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

void DwellWatch::stop(MeasureStatus s, std::string why) {
  if (stopped_) return;
  stopped_.emplace(s, std::move(why));
  spdlog::warn("robodamp measure: {}", stopped_->second);
  cell_->request_stop();
}

void DwellWatch::watch_rest(const rt::TelemetryFrame& f) {
  const double a = std::isfinite(f.accel_mps2) ? f.accel_mps2 : 0.0;
  rest_sum_ += a * a - rest_sq_[rest_at_];
  rest_sq_[rest_at_] = a * a;
  rest_at_ = (rest_at_ + 1) % rest_sq_.size();
  rest_n_ = std::min(rest_n_ + 1, rest_sq_.size());
}

double DwellWatch::rest_rms_mps2() const {
  return rest_n_ == 0 ? 0.0 : std::sqrt(std::max(0.0, rest_sum_) / static_cast<double>(rest_n_));
}

void DwellWatch::watch_chirp(const rt::TelemetryFrame& f) {
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

bool DwellWatch::moved(const std::vector<double>& q) const {
  if (q.empty() || q.size() != ref_.size()) return true;  // not known yet (or lost): not standing anywhere
  for (std::size_t i = 0; i < q.size(); ++i)
    if (std::abs(q[i] - ref_[i]) > o_.still_deg) return true;
  return false;
}

void DwellWatch::skip(const std::string& why) {
  dwells_.back().skipped = why;
  spdlog::warn("robodamp measure: dwell {} not measured: {}", dwells_.back().index, why);
}

void DwellWatch::on_move(double t_s) {
  if (phase_ == Phase::kMoving) return;
  DwellMeasurement& d = dwells_.back();
  if (phase_ == Phase::kStill && t_s - d.still_s < settle_s_) {
    // A pause, not a stop: no chirp could have started, and no hammer either (the plant side's stops last a
    // whole plan). It takes no number, so the dwells keep the emulator's numbering (dwell_<k>) even where the
    // joints' readings lag during a move (polled on the wall clock while the loop runs on the virtual one).
    ++pauses_;
    spdlog::info(
        "robodamp measure: the robot paused {:.2f} s at {}, shorter than commissioning.settle_s = {} s: "
        "not a stop",
        t_s - d.still_s, config::describe_pose(ref_), settle_s_);
    dwells_.pop_back();
    phase_ = Phase::kMoving;
    return;
  }
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

void DwellWatch::step(const rt::TelemetryFrame& f) {
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
      if (t < dwells_.back().still_s + plan_.duration_s) return;  // the plant side's hammer, on a stopped plan's times
      phase_ = Phase::kDone;
      if (measured_stops(dwells_) >= o_.dwells) cell_->request_stop();
      return;
    case Phase::kDone:
      return;
  }
}

void DwellWatch::start_chirp(const rt::TelemetryFrame& f) {
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

void DwellWatch::accumulate_pose() {
  DwellMeasurement& d = dwells_.back();
  if (d.joints_deg.empty()) d.joints_deg.assign(ref_.size(), 0.0), pose_n_ = 0;
  const std::vector<double> q = cell_->robot_pose_deg();
  if (q.size() != d.joints_deg.size()) return;
  ++pose_n_;
  for (std::size_t i = 0; i < q.size(); ++i) d.joints_deg[i] += (q[i] - d.joints_deg[i]) / static_cast<double>(pose_n_);
}

}  // namespace robodamp::commission
