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
                         r.damped, r.trigger, r.pose_deg);
}

}  // namespace

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
  return s;
}

SpeedAdvisor::SpeedAdvisor(milling::LiveStability& stability, std::function<AdviceView()> view, double rpm_min,
                           double rpm_max, std::function<void(const AdviceRecord&)> on_advice, double period_s,
                           milling::SpeedAdviceSettings s)
    : stability_(stability), view_(std::move(view)), on_advice_(std::move(on_advice)), rpm_min_(rpm_min),
      rpm_max_(rpm_max), period_s_(period_s), s_(std::move(s)) {
  s_.cancelled = [this] {
    std::lock_guard<std::mutex> lock(m_);
    return stop_;
  };
  thread_ = std::thread([this] { run(); });
}

SpeedAdvisor::~SpeedAdvisor() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

std::optional<AdviceRecord> SpeedAdvisor::latest() const {
  std::lock_guard<std::mutex> lock(m_);
  return latest_;
}

std::optional<milling::SpeedAdviceRequest> SpeedAdvisor::wanted(const AdviceView& v, bool gain_settled) {
  const dds::MachiningSample& m = v.sample;
  if (!(m.spindle_rpm > 0.0) || !gain_settled) return std::nullopt;
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
  return r;
}

void SpeedAdvisor::run() {
  std::optional<decltype(state_key(milling::SpeedAdviceRequest{}))> last;
  std::uint64_t seq = 0;
  double last_gain = -1.0;
  std::unique_lock<std::mutex> lock(m_);
  while (!cv_.wait_for(lock, std::chrono::duration<double>(period_s_), [this] { return stop_; })) {
    lock.unlock();
    const AdviceView v = view_();
    const bool settled = std::abs(v.gain_ns_per_m - last_gain) <= 1e-3 * std::abs(v.gain_ns_per_m);
    last_gain = v.gain_ns_per_m;
    const auto r = wanted(v, settled);
    if (r && state_key(*r) != last) {
      last = state_key(*r);
      try {
        AdviceRecord rec{++seq, v.sample.time_s, milling::advise_speed(stability_, *r, rpm_min_, rpm_max_, s_)};
        const auto& a = rec.advice;
        if (s_.cancelled()) return;
        if (a.found)
          spdlog::info("speed advice #{} ({} at {:.0f} rpm, {:.3f} mm{} against a limit of {:.3f} mm): {:.0f} rpm allows {:.3f} mm ({})",
                       rec.seq, r->trigger, r->rpm, a.depth_mm, a.depth_from_chatter ? " (the limit where it chatters)" : "",
                       a.limit_now_mm, a.options.front().rpm, a.options.front().limit_mm, a.method);
        else
          spdlog::warn("speed advice #{} ({} at {:.0f} rpm): {}", rec.seq, r->trigger, r->rpm, a.reason);
        if (on_advice_) on_advice_(rec);
        lock.lock();
        latest_ = std::move(rec);
        lock.unlock();
      } catch (const std::exception& e) {  // a request the analysis cannot answer: said, never thrown at the cell
        spdlog::warn("speed advice: {}", e.what());
      }
    }
    lock.lock();
  }
}

}  // namespace robodamp::runtime
