// The robot program's next poses over DDS (dds.path_ahead, docs/pose_dynamics.md, "Advice along the path
// ahead"): each message is ROS 2's trajectory_msgs/msg/JointTrajectory as a program sends it to its joint
// trajectory controller (joint_names, points with positions in rad and time_from_start). The pose
// schedule's joints are found by name and turned to degrees; a point stays ahead until its time_from_start
// has passed since the message arrived (an untimed point, time_from_start 0, for hold_s). A new message
// replaces the path; one that lacks a joint or has a point of the wrong length or not finite is refused
// whole (counted, warned once per kind) and leaves the last path. Off the real-time path: on_message on the
// DDS listener's thread, poses_deg on the speed advisor's.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "config/supervisory_config.hpp"
#include "dds/bridge.hpp"
#include "fields/fields.hpp"

namespace robodamp::runtime {

struct PathAheadCounters {
  std::uint64_t messages{0};
  std::uint64_t refused{0};
};

// PathAheadCounters' JSON keys (the run summary's "path_ahead") and their words in its text line.
[[nodiscard]] constexpr auto field_list(fields::Tag<PathAheadCounters>) {
  using P = PathAheadCounters;
  using F = fields::Field<P, std::uint64_t>;
  return std::tuple{F{"messages", &P::messages, "trajectories"},
                    F{"refused", &P::refused, "refused (a joint missing, a point short or not finite)"}};
}
static_assert(fields::lists_every_member<PathAheadCounters>(), "each counter in PathAheadCounters' field list");

using TrajectoryPoint = dds::TrajectoryPoint;  // one point as the message carries it

class PathAhead {
 public:
  using Clock = std::chrono::steady_clock;
  // names: the pose schedule's joints in its order, as the program names them.
  PathAhead(config::PathAheadConfig cfg, std::vector<std::string> names);

  void on_message(const std::vector<std::string>& joint_names, const std::vector<TrajectoryPoint>& points,
                  Clock::time_point now = Clock::now());
  // The poses still ahead at `now`, in the message's order, in degrees (empty: none).
  [[nodiscard]] std::vector<std::vector<double>> poses_deg(Clock::time_point now = Clock::now()) const;
  [[nodiscard]] PathAheadCounters counters() const;

 private:
  struct Due {
    std::vector<double> joints_deg;
    Clock::time_point until;
  };
  config::PathAheadConfig cfg_;
  std::vector<std::string> names_;
  mutable std::mutex m_;
  std::vector<Due> path_;
  std::string last_problem_;
  PathAheadCounters n_;
};

}  // namespace robodamp::runtime
