// The cell's spindle-speed advisor (docs/milling.md, "Spindle-speed advice"): a thread of its own looks at
// the machining view every period_s and, when the cut chatters (the live indicator) or the job's depth is
// above the limit that applies at the speed now, works out the advice for that state once
// (milling::advise_speed: the accurate limits at each candidate speed, seconds). Each new advice gets the
// next sequence number; the DDS advice topic, the robot's Modbus registers and the run summary carry the
// latest. Off the real-time path.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "dds/bridge.hpp"
#include "milling/live_stability.hpp"
#include "milling/speed_advice.hpp"

namespace robodamp::runtime {

struct AdviceRecord {
  std::uint64_t seq{0};        // 1, 2, ...: one per new advice
  double time_s{0.0};          // the loop time of the view that asked for it
  milling::SpeedAdvice advice;
};

// What the advisor reads of the cell's machining view, and the state an advice is for.
struct AdviceView {
  dds::MachiningSample sample;
  std::size_t parameter_set{0};
  double gain_ns_per_m{0.0};   // the gain the damped limit is for
  std::function<std::pair<std::size_t, double>(double rpm)> controller_at{};  // a speed schedule's (empty: none)
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
  // the gain the same as a period ago (an advice during a fade would be for a passing state).
  [[nodiscard]] static std::optional<milling::SpeedAdviceRequest> wanted(const AdviceView& v, bool gain_settled);

 private:
  void run();

  milling::LiveStability& stability_;
  std::function<AdviceView()> view_;
  std::function<void(const AdviceRecord&)> on_advice_;
  double rpm_min_, rpm_max_, period_s_;
  milling::SpeedAdviceSettings s_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  bool stop_{false};
  std::optional<AdviceRecord> latest_;
  std::thread thread_;
};

}  // namespace robodamp::runtime
