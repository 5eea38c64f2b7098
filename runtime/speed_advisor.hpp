// The cell's spindle-speed advisor (docs/milling.md, "Spindle-speed advice"): a thread of its own looks at
// the machining view every period_s and, when the cut chatters (the live indicator) or the job's depth is
// above the limit that applies at the speed now, works out the advice for that state once
// (milling::advise_speed: the accurate limits at each candidate speed, seconds). Each new advice gets the
// next sequence number; the DDS advice topic, the robot's Modbus registers and the run summary carry the
// latest. The latest advice has a status, looked at every period: current while the state it was for holds,
// followed once the spindle turns at the advised speed, expired (with the reason) when the state it was for
// is gone without it; each change is logged and published. Off the real-time path.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <stop_token>
#include <utility>

#include "dds/bridge.hpp"
#include "milling/live_stability.hpp"
#include "milling/speed_advice.hpp"
#include "threads/worker.hpp"

namespace robodamp::runtime {

enum class AdviceStatus : std::uint8_t { kCurrent, kFollowed, kExpired };
[[nodiscard]] const char* to_string(AdviceStatus s);

struct AdviceRecord {
  std::uint64_t seq{0};  // 1, 2, ...: one per new advice
  double time_s{0.0};    // the loop time of the view that asked for it
  milling::SpeedAdvice advice;
  AdviceStatus status{AdviceStatus::kCurrent};
  std::string status_reason;  // followed or expired: what the advisor saw (empty while current)
  double status_time_s{0.0};  // the loop time of the view that changed the status
};

// What the advisor reads of the cell's machining view, and the state an advice is for.
struct AdviceView {
  dds::MachiningSample sample;
  std::size_t parameter_set{0};
  double gain_ns_per_m{0.0};  // the gain the damped limit is for
  // A parameter-set hand-over under way (a speed or pose schedule's, a request's): the set and K above are
  // the outgoing chain's, fading out or held at 0 while the incoming one warms up; no advice is asked for them.
  bool handing_over{false};
  std::function<std::pair<std::size_t, double>(double rpm)> controller_at{};  // a speed schedule's (empty: none)
  // The robot program's next poses (dds.path_ahead; empty: none published) and the set and K the pose
  // schedule would run at each (milling::SpeedAdviceRequest).
  std::vector<std::vector<double>> path_ahead_deg;
  std::function<std::pair<std::size_t, double>(const std::vector<double>& pose_deg, double rpm)> controller_at_pose{};
};

// The record as the DDS advice topic carries it.
[[nodiscard]] dds::AdviceSample to_sample(const AdviceRecord& r);

class SpeedAdvisor {
 public:
  // on_advice (optional): called on the advisor's thread with each new advice (the robot's registers).
  SpeedAdvisor(milling::LiveStability& stability, std::function<AdviceView()> view, double rpm_min, double rpm_max,
               std::function<void(const AdviceRecord&)> on_advice = {}, double period_s = 0.2,
               milling::SpeedAdviceSettings s = {});
  ~SpeedAdvisor();
  SpeedAdvisor(const SpeedAdvisor&) = delete;
  SpeedAdvisor& operator=(const SpeedAdvisor&) = delete;

  // Any thread: the latest advice (none yet: nothing asked for one).
  [[nodiscard]] std::optional<AdviceRecord> latest() const;
  // Whether the view now asks for advice, and for which request (the trigger set), or not. gain_settled:
  // the gain the same as a period ago (an advice during a fade would be for a passing state); nor during a
  // hand-over (AdviceView::handing_over), whose outgoing chain sits at K = 0 through the incoming one's warm-up.
  [[nodiscard]] static std::optional<milling::SpeedAdviceRequest> wanted(const AdviceView& v, bool gain_settled);
  // The advice's status in the view now: followed at the advised speed (within same_speed_rpm); expired
  // when the spindle stopped or turns at another speed (not on its way to the advised one; on its way the
  // rest is not looked at: a speed schedule changes the set and K with the speed), or at its speed the set, the gain, the damper, the depth or the pose
  // changed, or neither chatter nor a depth above the limit asks any more; else current. With the reason
  // (empty while current).
  [[nodiscard]] static std::pair<AdviceStatus, std::string> status_in(const AdviceRecord& r, const AdviceView& v);
  // How far a spindle's speed may be from a speed and still be it: 0.2 % (0.5 rpm at least). A spindle turns
  // at what its drive can: the HIL emulator at a whole number of its 5 kHz samples per tooth, 666.7 rpm for
  // an advised 666.0 (0.1 %); the register's resolution is 0.1 rpm.
  [[nodiscard]] static double same_speed_rpm(double rpm) { return std::max(0.5, 0.002 * rpm); }

 private:
  void run(std::stop_token stop);
  bool follow_status(const AdviceView& v);

  milling::LiveStability& stability_;
  std::function<AdviceView()> view_;
  std::function<void(const AdviceRecord&)> on_advice_;
  double rpm_min_, rpm_max_, period_s_;
  milling::SpeedAdviceSettings s_;
  mutable std::mutex m_;
  std::optional<AdviceRecord> latest_;
  threads::Worker worker_;  // last: started after everything it reads
};

}  // namespace robodamp::runtime
