// The robot's pose from a ROS 2 driver's joint states over DDS (dds.joint_states, docs/pose_dynamics.md,
// "The pose over DDS"): each message's positions (rad) for the pose schedule's joints, found by name, to
// degrees; the region they fall in once it has held for settle_samples messages in a row, as the Modbus joint
// registers do (config::PoseSettling); no message for timeout_s, or a message that lacks a joint, leaves the
// pose unknown (out of the map: the schedule's region 0 set runs, as for the registers). Off the real-time
// path: on_message on the DDS listener's thread, check on the bridge's status thread.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "config/pose_schedule_config.hpp"
#include "config/supervisory_config.hpp"
#include "fields/fields.hpp"

namespace robodamp::runtime {

struct JointStateCounters {
  std::uint64_t messages{0};
  std::uint64_t refused{0};     // a joint missing, position and name of different lengths, or not finite
  std::uint64_t out_of_map{0};  // messages whose pose no region holds
  std::uint64_t changes{0};     // regions reported (out of the map included)
  std::uint64_t losses{0};      // silences of timeout_s
};

// JointStateCounters' JSON keys (the run summary's "joint_states") and their words in its text line.
[[nodiscard]] constexpr auto field_list(fields::Tag<JointStateCounters>) {
  using J = JointStateCounters;
  using F = fields::Field<J, std::uint64_t>;
  return std::tuple{F{"messages", &J::messages, "messages"},
                    F{"refused", &J::refused, "refused (a joint missing or not finite)"},
                    F{"out_of_map", &J::out_of_map, "out of the map"}, F{"changes", &J::changes, "pose changes"},
                    F{"losses", &J::losses, "silences"}};
}
static_assert(fields::lists_every_member<JointStateCounters>(), "each counter in JointStateCounters' field list");

class JointStatePose {
 public:
  using Clock = std::chrono::steady_clock;
  JointStatePose(config::JointStatesConfig cfg, config::PoseScheduleConfig schedule,
                 std::function<void(std::optional<std::size_t>)> on_region);

  // One message: the names and positions (rad) as the driver sent them.
  void on_message(const std::vector<std::string>& names, const std::vector<double>& position_rad,
                  Clock::time_point now = Clock::now());
  // The silence check (any thread, periodically).
  void check(Clock::time_point now = Clock::now());

  // The last accepted pose; empty before one and while the pose is unknown (a refused message, a silence).
  [[nodiscard]] std::vector<double> joints_deg() const;
  [[nodiscard]] JointStateCounters counters() const;

 private:
  void report(long region);  // under m_
  config::JointStatesConfig cfg_;
  config::PoseScheduleConfig schedule_;
  std::function<void(std::optional<std::size_t>)> on_region_;
  mutable std::mutex m_;
  config::PoseSettling settling_;
  std::vector<double> joints_deg_;
  Clock::time_point last_{};
  bool heard_{false}, lost_{false};
  std::string last_problem_;
  JointStateCounters n_;
};

}  // namespace robodamp::runtime
