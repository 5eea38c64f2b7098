#include "runtime/speed_advisor.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <tuple>

#include <spdlog/spdlog.h>

namespace robodamp::runtime {

namespace {

// The state an advice is for: the same one is not advised twice in a row.
auto state_key(const milling::SpeedAdviceRequest& r) {
  return std::make_tuple(std::lround(r.rpm), std::lround(r.depth_mm * 1e3), r.set, std::lround(r.gain_ns_per_m / 10.0),
                         r.damped, r.trigger, r.pose_deg, r.path_ahead_deg);
}

}  // namespace

const char* to_string(AdviceStatus s) {
  switch (s) {
    case AdviceStatus::kCurrent:
      return "current";
    case AdviceStatus::kFollowed:
      return "followed";
    case AdviceStatus::kExpired:
      return "expired";
  }
  return "?";
}

dds::AdviceSample to_sample(const AdviceRecord& r) {
  const milling::SpeedAdvice& a = r.advice;
  dds::AdviceSample s;
  s.seq = r.seq;
  s.time_s = r.time_s;
  s.trigger = a.request.trigger;
  s.spindle_rpm = a.request.rpm;
  s.depth_mm = a.depth_mm;  // what the margins are against (the limit where it chatters when above the told depth)
  s.damped = a.request.damped;
  s.chatter_hz = a.request.chatter_hz;
  s.limit_now_mm = a.limit_now_mm;
  s.method = a.method;
  s.found = a.found;
  if (a.found) {
    s.advised_rpm = a.options.front().rpm;
    s.advised_limit_mm = a.options.front().limit_mm;
    s.margin = a.options.front().margin;
  }
  for (const auto& o : a.options) s.option_rpm.push_back(o.rpm), s.option_limit_mm.push_back(o.limit_mm);
  s.best_rpm = a.best.rpm;
  s.best_limit_mm = a.best.limit_mm;
  s.reason = a.reason;
  s.rpm_min = a.rpm_min;
  s.rpm_max = a.rpm_max;
  s.pose_deg = a.request.pose_deg;
  s.poses_ahead = a.poses_checked.empty() ? 0U : static_cast<std::uint32_t>(a.poses_checked.size() - 1);
  s.limiting_pose_deg = a.found ? a.options.front().limiting_pose_deg : a.best.limiting_pose_deg;
  s.status = to_string(r.status);
  s.status_reason = r.status_reason;
  return s;
}

SpeedAdvisor::SpeedAdvisor(milling::LiveStability& stability, std::function<AdviceView()> view, double rpm_min,
                           double rpm_max, std::function<void(const AdviceRecord&)> on_advice, double period_s,
                           milling::SpeedAdviceSettings s)
    : stability_(stability),
      view_(std::move(view)),
      on_advice_(std::move(on_advice)),
      rpm_min_(rpm_min),
      rpm_max_(rpm_max),
      period_s_(period_s),
      s_(std::move(s)) {
  worker_.start("rd-speed-advice", [this](std::stop_token stop) { run(stop); });
}

SpeedAdvisor::~SpeedAdvisor() { worker_.stop(); }

std::optional<AdviceRecord> SpeedAdvisor::latest() const {
  std::lock_guard<std::mutex> lock(m_);
  return latest_;
}

std::optional<milling::SpeedAdviceRequest> SpeedAdvisor::wanted(const AdviceView& v, bool gain_settled) {
  const dds::MachiningSample& m = v.sample;
  if (!(m.spindle_rpm > 0.0) || !gain_settled || v.handing_over) return std::nullopt;
  milling::SpeedAdviceRequest r;
  if (m.indicator_valid && m.chatter) {
    r.trigger = "chatter";
    r.chatter_hz = m.chatter_hz;
  } else if (m.limits_ready && m.depth_warning) {
    r.trigger = "depth above the limit";
  } else {
    return std::nullopt;
  }
  r.rpm = m.spindle_rpm;
  r.depth_mm = m.depth_mm;
  r.set = v.parameter_set;
  r.gain_ns_per_m = v.gain_ns_per_m;
  r.controller_at = v.controller_at;
  r.damped = m.loop_active;
  r.pose_deg = m.limits_pose_deg;
  if (!r.pose_deg.empty()) r.path_ahead_deg = v.path_ahead_deg, r.controller_at_pose = v.controller_at_pose;
  return r;
}

std::pair<AdviceStatus, std::string> SpeedAdvisor::status_in(const AdviceRecord& r, const AdviceView& v) {
  const milling::SpeedAdviceRequest& q = r.advice.request;
  const dds::MachiningSample& m = v.sample;
  const double rpm = m.spindle_rpm;
  if (r.advice.found && rpm > 0.0 &&
      std::abs(rpm - r.advice.options.front().rpm) <= same_speed_rpm(r.advice.options.front().rpm))
    return {AdviceStatus::kFollowed, fmt::format("the spindle at the advised {:.1f} rpm", rpm)};
  if (!(rpm > 0.0)) return {AdviceStatus::kExpired, "the spindle stopped"};
  // A spindle ramping from the speed it was asked at to the advised one is following it, not elsewhere.
  const double to = r.advice.found ? r.advice.options.front().rpm : q.rpm, near = same_speed_rpm(q.rpm);
  const bool on_the_way = rpm >= std::min(q.rpm, to) - near && rpm <= std::max(q.rpm, to) + near;
  if (!on_the_way)
    return {AdviceStatus::kExpired,
            fmt::format("the spindle at {:.1f} rpm, not the {:.1f} rpm it was for", rpm, q.rpm)};
  // On its way, a speed schedule's set and K follow the speed: what else it was for counts at its own speed.
  if (std::abs(rpm - q.rpm) > near) return {AdviceStatus::kCurrent, ""};
  if (v.parameter_set != q.set)
    return {AdviceStatus::kExpired, fmt::format("parameter set {} runs, not set {}", v.parameter_set, q.set)};
  if (std::abs(v.gain_ns_per_m - q.gain_ns_per_m) > std::max(10.0, 0.01 * std::abs(q.gain_ns_per_m)))
    return {AdviceStatus::kExpired,
            fmt::format("K = {:.0f} N s/m, not the {:.0f} N s/m it was for", v.gain_ns_per_m, q.gain_ns_per_m)};
  if (m.loop_active != q.damped)
    return {AdviceStatus::kExpired, m.loop_active ? "the damper active now" : "the damper off now"};
  if (std::abs(m.depth_mm - q.depth_mm) > 1e-3)
    return {AdviceStatus::kExpired,
            fmt::format("the depth {:.3f} mm, not the {:.3f} mm it was for", m.depth_mm, q.depth_mm)};
  if (m.limits_pose_deg != q.pose_deg) return {AdviceStatus::kExpired, "the robot moved to another pose"};
  if (m.indicator_valid && !m.chatter && m.limits_ready && !m.depth_warning)
    return {AdviceStatus::kExpired, "no chatter and the depth within the limit now"};
  return {AdviceStatus::kCurrent, ""};
}

// Under no lock: the latest advice's status in the view now; a change is logged, stored and handed on (the
// robot's registers withdraw an expired advice). Followed and expired are final: the state an expired advice
// was for may come back, and then it is asked for again (returns true: forget the last state advised).
bool SpeedAdvisor::follow_status(const AdviceView& v) {
  std::unique_lock<std::mutex> lock(m_);
  if (!latest_ || latest_->status != AdviceStatus::kCurrent) return false;
  auto [status, reason] = status_in(*latest_, v);
  if (status == AdviceStatus::kCurrent) return false;
  latest_->status = status, latest_->status_reason = std::move(reason), latest_->status_time_s = v.sample.time_s;
  const AdviceRecord rec = *latest_;
  lock.unlock();
  spdlog::info("speed advice #{} {} at {:.3f} s: {}", rec.seq, to_string(rec.status), rec.status_time_s,
               rec.status_reason);
  if (on_advice_) on_advice_(rec);
  return status == AdviceStatus::kExpired;
}

void SpeedAdvisor::run(std::stop_token stop) {
  std::optional<decltype(state_key(milling::SpeedAdviceRequest{}))> last;
  std::uint64_t seq = 0;
  double last_gain = -1.0;
  s_.cancelled = [stop] { return stop.stop_requested(); };  // the cell shutting down ends a search between candidates
  while (worker_.sleep_for(stop, std::chrono::duration<double>(period_s_))) {
    const AdviceView v = view_();
    const bool settled = std::abs(v.gain_ns_per_m - last_gain) <= 1e-3 * std::abs(v.gain_ns_per_m);
    last_gain = v.gain_ns_per_m;
    if (follow_status(v)) last.reset();
    const auto r = wanted(v, settled);
    if (r && state_key(*r) != last) {
      last = state_key(*r);
      try {
        AdviceRecord rec;
        rec.seq = ++seq;
        rec.time_s = v.sample.time_s;
        rec.advice = milling::advise_speed(stability_, *r, rpm_min_, rpm_max_, s_);
        const auto& a = rec.advice;
        if (s_.cancelled()) return;
        if (a.found)
          spdlog::info(
              "speed advice #{} ({} at {:.0f} rpm, {:.3f} mm{} against a limit of {:.3f} mm): {:.0f} rpm allows {:.3f} "
              "mm ({})",
              rec.seq, r->trigger, r->rpm, a.depth_mm, a.depth_from_chatter ? " (the limit where it chatters)" : "",
              a.limit_now_mm, a.options.front().rpm, a.options.front().limit_mm, a.method);
        else
          spdlog::warn("speed advice #{} ({} at {:.0f} rpm): {}", rec.seq, r->trigger, r->rpm, a.reason);
        if (on_advice_) on_advice_(rec);
        std::lock_guard<std::mutex> lock(m_);
        latest_ = std::move(rec);
      } catch (const std::exception& e) {  // a request the analysis cannot answer: said, never thrown at the cell
        spdlog::warn("speed advice: {}", e.what());
      }
    }
  }
}

}  // namespace robodamp::runtime
