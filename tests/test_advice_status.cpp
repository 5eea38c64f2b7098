// An advice lives as long as the state it was for (issue 52, runtime/speed_advisor.hpp): current while it
// holds, followed at the advised speed, expired (with the reason) when the state is gone without it.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/live_stability.hpp"
#include "runtime/speed_advisor.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using runtime::AdviceStatus;

std::string job_file() { return std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml"; }

// An advice asked at 700 rpm, 1.0 mm, damped with set 1 at K = 2000 N s/m, found at 666.7 rpm.
runtime::AdviceRecord advised() {
  runtime::AdviceRecord r;
  r.seq = 3;
  milling::SpeedAdviceRequest& q = r.advice.request;
  q.rpm = 700.0, q.depth_mm = 1.0, q.set = 1, q.gain_ns_per_m = 2000.0, q.damped = true,
  q.trigger = "depth above the limit";
  r.advice.found = true;
  r.advice.options.push_back({666.7, 1.74, 1.74, "mode", {}});
  return r;
}

runtime::AdviceView state_asked() {
  runtime::AdviceView v;
  v.sample.spindle_rpm = 700.0, v.sample.depth_mm = 1.0, v.sample.loop_active = true;
  v.sample.limits_ready = v.sample.depth_warning = true;
  v.parameter_set = 1, v.gain_ns_per_m = 2000.0;
  return v;
}

// Each way the state can go, one at a time, and the reason said.
TEST(AdviceStatus, EachChangeOfTheStateItWasForExpiresItWithTheReason) {
  const runtime::AdviceRecord r = advised();
  auto expect = [&](const runtime::AdviceView& v, AdviceStatus s, const std::string& reason) {
    const auto [status, said] = runtime::SpeedAdvisor::status_in(r, v);
    EXPECT_EQ(runtime::to_string(status), std::string(runtime::to_string(s))) << reason;
    EXPECT_NE(said.find(reason), std::string::npos) << said;
    if (s == AdviceStatus::kCurrent) {
      EXPECT_TRUE(said.empty()) << said;
    }
  };
  runtime::AdviceView v = state_asked();
  expect(v, AdviceStatus::kCurrent, "");
  v.sample.spindle_rpm = 701.4;  // within 0.2 % (SpeedAdvisor::same_speed_rpm)
  expect(v, AdviceStatus::kCurrent, "");
  v.sample.spindle_rpm = 667.9;  // the advised 666.7 rpm, as a drive turns it
  expect(v, AdviceStatus::kFollowed, "the spindle at the advised 667.9 rpm");
  v.sample.spindle_rpm = 685.0;  // ramping from 700 to the advised 666.7 rpm: on its way
  expect(v, AdviceStatus::kCurrent, "");
  v.parameter_set = 0, v.gain_ns_per_m = 3040.0;  // a speed schedule's band crossed on the way
  expect(v, AdviceStatus::kCurrent, "");
  v.parameter_set = 1, v.gain_ns_per_m = 2000.0;
  v.sample.spindle_rpm = 665.2;
  expect(v, AdviceStatus::kExpired, "the spindle at 665.2 rpm, not the 700.0 rpm it was for");
  v.sample.spindle_rpm = 702.0;
  expect(v, AdviceStatus::kExpired, "the spindle at 702.0 rpm, not the 700.0 rpm it was for");
  v.sample.spindle_rpm = 720.0;
  expect(v, AdviceStatus::kExpired, "the spindle at 720.0 rpm, not the 700.0 rpm it was for");
  v.sample.spindle_rpm = 0.0;
  expect(v, AdviceStatus::kExpired, "the spindle stopped");
  v = state_asked(), v.parameter_set = 0;
  expect(v, AdviceStatus::kExpired, "parameter set 0 runs, not set 1");
  v = state_asked(), v.gain_ns_per_m = 1000.0;
  expect(v, AdviceStatus::kExpired, "K = 1000 N s/m, not the 2000 N s/m it was for");
  v.gain_ns_per_m = 2015.0;  // within 1 % (a gain read back through the ramp's arithmetic)
  expect(v, AdviceStatus::kCurrent, "");
  v = state_asked(), v.sample.loop_active = false;
  expect(v, AdviceStatus::kExpired, "the damper off now");
  v = state_asked(), v.sample.depth_mm = 0.8;
  expect(v, AdviceStatus::kExpired, "the depth 0.800 mm, not the 1.000 mm it was for");
  v = state_asked(), v.sample.limits_pose_deg = {0.0, 30.0, -60.0};
  expect(v, AdviceStatus::kExpired, "the robot moved to another pose");
  v = state_asked(), v.sample.depth_warning = false;  // no verdict from the indicator yet: still asked
  expect(v, AdviceStatus::kCurrent, "");
  v.sample.indicator_valid = true;
  expect(v, AdviceStatus::kExpired, "no chatter and the depth within the limit now");
  v.sample.chatter = true;
  expect(v, AdviceStatus::kCurrent, "");
  // No speed found: nothing to follow; the state's changes expire it the same way.
  runtime::AdviceRecord none = r;
  none.advice.found = false, none.advice.options.clear();
  v = state_asked();
  EXPECT_EQ(runtime::SpeedAdvisor::status_in(none, v).first, AdviceStatus::kCurrent);
  v.sample.spindle_rpm = 666.7;
  EXPECT_EQ(runtime::SpeedAdvisor::status_in(none, v).first, AdviceStatus::kExpired);
  // As the topic carries it.
  runtime::AdviceRecord gone = r;
  gone.status = AdviceStatus::kExpired, gone.status_reason = "the spindle stopped";
  const dds::AdviceSample s = runtime::to_sample(gone);
  EXPECT_EQ(s.status, "expired");
  EXPECT_EQ(s.status_reason, "the spindle stopped");
}

// The advisor's thread on the default job (open loop, 1.5 mm at 700 rpm: above the open limit of 1.106 mm):
// the advice; the spindle turned elsewhere (faster, away from the advised 666 rpm) expires it (handed on once: the robot's registers withdraw it);
// back at 700 rpm the same state asks again (a new number); the spindle at the advised speed follows it.
// Each status once: the calls are counted after the thread has been joined.
TEST(AdviceStatus, TheAdvisorExpiresAndFollowsItsAdviceOnItsOwnThread) {
  const config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  milling::LiveStability stability(config::load_milling_config(job_file()), "", {cfg});
  std::mutex m;
  runtime::AdviceView now = state_asked();
  now.sample.depth_mm = 1.5, now.sample.loop_active = false, now.parameter_set = 0, now.gain_ns_per_m = 0.0;
  std::vector<runtime::AdviceRecord> told;
  auto set = [&](double rpm, bool above) {
    std::lock_guard<std::mutex> lock(m);
    now.sample.spindle_rpm = rpm, now.sample.depth_warning = above;
  };
  auto count = [&] {
    std::lock_guard<std::mutex> lock(m);
    return told.size();
  };
  {
    runtime::SpeedAdvisor advisor(
        stability,
        [&] {
          std::lock_guard<std::mutex> lock(m);
          return now;
        },
        100.0, 1500.0,
        [&](const runtime::AdviceRecord& r) {
          std::lock_guard<std::mutex> lock(m);
          told.push_back(r);
        },
        0.02);
    ASSERT_TRUE(test::eventually([&] { return count() >= 1; }, 300.0));
    ASSERT_TRUE(told[0].advice.found) << told[0].advice.reason;
    EXPECT_EQ(told[0].seq, 1U);
    EXPECT_EQ(told[0].status, AdviceStatus::kCurrent);
    set(720.0, false);
    ASSERT_TRUE(test::eventually([&] { return count() >= 2; }, 30.0));
    EXPECT_EQ(told[1].seq, 1U);
    EXPECT_EQ(told[1].status, AdviceStatus::kExpired);
    EXPECT_EQ(told[1].status_reason, "the spindle at 720.0 rpm, not the 700.0 rpm it was for");
    EXPECT_EQ(advisor.latest()->status, AdviceStatus::kExpired);
    set(700.0, true);
    ASSERT_TRUE(test::eventually([&] { return count() >= 3; }, 300.0));
    EXPECT_EQ(told[2].seq, 2U);
    EXPECT_EQ(told[2].status, AdviceStatus::kCurrent);
    ASSERT_TRUE(told[2].advice.found);
    const double go = told[2].advice.options.front().rpm;
    set(go, false);
    ASSERT_TRUE(test::eventually([&] { return count() >= 4; }, 30.0));
    EXPECT_EQ(told[3].seq, 2U);
    EXPECT_EQ(told[3].status, AdviceStatus::kFollowed);
    EXPECT_NE(told[3].status_reason.find("the advised"), std::string::npos) << told[3].status_reason;
    // A few more looks at the followed state (the period is 20 ms), then the thread joined.
    const std::size_t looks = 10;
    for (std::size_t i = 0; i < looks; ++i) set(go, false), std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(told.size(), 4U) << "a status handed on twice";
}

}  // namespace
}  // namespace robodamp
