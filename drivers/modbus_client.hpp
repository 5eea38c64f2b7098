// The supervisory Modbus client (libmodbus, TCP or RTU): the amplifier's enable coil and its ready,
// fault and temperature registers, and the robot controller's mounting register, polled on threads of
// their own (one per device, so a device that hangs does not stall the other). The loop's real-time
// thread only touches atomics: request_amplifier_enable() stores the wish, amplifier_status() reads
// what the last successful poll saw.
//
// - A failed call (timeout, reset, refused connection) closes the link; it reconnects after a back-off
//   that doubles from modbus.backoff_initial_s up to modbus.backoff_max_s and resets on success.
// - No successful poll for modbus.link_timeout_s while the amplifier is enabled or asked to be: its
//   state is unknown, and amplifier_status() reports the link lost (the supervisor trips on the actuator path). While the loop
//   does not need the amplifier a lost link is only counted.
// - The amplifier is reported faulty above modbus.amplifier.temperature_max_c too.
// - The robot's mounting (horizontal / vertical value) must read the same settle_polls polls running
//   before the callback is told; the session turns that into a parameter-set selection the supervisor
//   validates and the controller hands over with a fade (never a switch mid-cycle).
// - The robot's joint angles (pose_schedule, modbus.robot.joints_register): the region the pose is in
//   (or "out of the map") must read the same settle_polls polls running before the callback is told; a
//   register holding -32768 (not available) reads as out of the map, and no successful poll for
//   link_timeout_s makes the pose unknown (out of the map) as well.
#pragma once

#include <array>
#include <atomic>
#include <limits>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <stop_token>
#include <vector>

#include "config/config.hpp"
#include "fields/fields.hpp"
#include "rt/io.hpp"
#include "threads/worker.hpp"

// libmodbus's own names (its modbus.h), declared here so that the header does not pull libmodbus in.
typedef struct _modbus modbus_t;  // NOLINT(bugprone-reserved-identifier)

namespace robodamp::drivers {

// One Modbus device's connection with reconnect back-off; used from one thread.
class ModbusLink {
 public:
  using Clock = std::chrono::steady_clock;
  ModbusLink(const config::ModbusEndpoint& endpoint, const config::ModbusConfig& timing);
  ~ModbusLink();
  ModbusLink(const ModbusLink&) = delete;
  ModbusLink& operator=(const ModbusLink&) = delete;

  // Connects if not connected and the back-off has passed. Null when not connected.
  modbus_t* connect(Clock::time_point now);
  // The last call failed: close, and wait out the back-off before the next attempt.
  void failed(Clock::time_point now);
  void succeeded() { backoff_ = initial_; }
  [[nodiscard]] bool connected() const { return ctx_ != nullptr && connected_; }
  [[nodiscard]] Clock::time_point retry_at() const { return retry_at_; }
  [[nodiscard]] std::chrono::duration<double> backoff() const { return backoff_; }
  [[nodiscard]] const std::string& last_error() const { return last_error_; }
  std::atomic<std::uint64_t> connects{0}, connect_failures{0}, errors{0}, timeouts{0};

 private:
  config::ModbusEndpoint ep_;
  std::chrono::duration<double> initial_, max_, backoff_, response_timeout_;
  modbus_t* ctx_{nullptr};
  bool connected_{false};
  Clock::time_point retry_at_{};
  std::string last_error_;
};

struct ModbusCounters {
  std::uint64_t amplifier_polls{0}, robot_polls{0};
  std::uint64_t connects{0}, connect_failures{0}, errors{0}, timeouts{0};
  std::uint64_t link_faults{0};  // times the amplifier's status became unknown while it mattered
  std::uint64_t coil_writes{0};
  std::uint64_t mounting_changes{0};         // selections handed to the callback
  std::uint64_t mounting_unknown{0};         // polls with a value that is neither horizontal nor vertical
  std::uint64_t spindle_changes{0};          // settled spindle speeds handed to the callback
  std::uint64_t spindle_link_parks{0};       // robot link lost for link_timeout_s: speed 0 handed over (notches parked)
  std::uint64_t pose_changes{0};             // settled regions (or out of the map) handed to the callback
  std::uint64_t pose_out_of_map_polls{0};    // polls with the pose outside every region
  std::uint64_t pose_unavailable_polls{0};   // polls with a joint register at -32768 (not available)
  std::uint64_t pose_link_losses{0};         // robot link lost for link_timeout_s: the pose became unknown
  std::uint64_t advice_writes{0};            // spindle-speed advices written to modbus.robot.advice_register
  std::uint64_t depth_changes{0};            // new depths read from modbus.robot.depth_register
  std::uint64_t depth_unavailable_polls{0};  // polls with the depth register at 65535 (not available)
};

// ModbusCounters' JSON keys (the run summary's "modbus") and their words in its text line.
[[nodiscard]] constexpr auto field_list(fields::Tag<ModbusCounters>) {
  using M = ModbusCounters;
  using F = fields::Field<M, std::uint64_t>;
  return std::tuple{F{"amplifier_polls", &M::amplifier_polls, "amplifier polls"},
                    F{"robot_polls", &M::robot_polls, "robot polls"},
                    F{"connects", &M::connects, "connects"},
                    F{"connect_failures", &M::connect_failures, "connects failed"},
                    F{"errors", &M::errors, "errors"},
                    F{"timeouts", &M::timeouts, "timeouts"},
                    F{"link_faults", &M::link_faults, "link faults"},
                    F{"coil_writes", &M::coil_writes, "coil writes"},
                    F{"mounting_changes", &M::mounting_changes, "mounting changes"},
                    F{"mounting_unknown", &M::mounting_unknown, "mountings unknown"},
                    F{"spindle_changes", &M::spindle_changes, "spindle speed changes"},
                    F{"spindle_link_parks", &M::spindle_link_parks, "notches parked (robot link lost)"},
                    F{"pose_changes", &M::pose_changes, "pose changes"},
                    F{"pose_out_of_map_polls", &M::pose_out_of_map_polls, "polls out of the map"},
                    F{"pose_unavailable_polls", &M::pose_unavailable_polls, "polls with the pose not available"},
                    F{"pose_link_losses", &M::pose_link_losses, "pose link losses"},
                    F{"advice_writes", &M::advice_writes, "speed advices written"},
                    F{"depth_changes", &M::depth_changes, "depth changes"},
                    F{"depth_unavailable_polls", &M::depth_unavailable_polls, "polls with the depth not available"}};
}
static_assert(fields::lists_every_member<ModbusCounters>(), "each counter in ModbusCounters' field list");

class ModbusClient final : public rt::AmplifierIo {
 public:
  using MountingCallback = std::function<void(config::Mounting)>;
  using SpindleCallback = std::function<void(double rpm)>;
  // The settled region's index in pose_schedule.regions, or nothing: out of the map or unknown.
  using PoseCallback = std::function<void(std::optional<std::size_t> region)>;
  // initial: the mounting the controller starts with (its configuration's actuator.mounting).
  ModbusClient(const config::ModbusConfig& cfg, config::Mounting initial, MountingCallback on_mounting = {});
  ~ModbusClient() override;
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

  // Before start(): called from the robot thread with each settled spindle speed (rpm; 0 when the robot
  // link has been lost for link_timeout_s). Needs modbus.robot.spindle_rpm_register.
  void set_spindle_callback(SpindleCallback cb) { on_spindle_ = std::move(cb); }
  // Before start(): the pose schedule the joint registers are classified by, and the callback (robot
  // thread). Needs modbus.robot.joints_register.
  void set_pose_callback(const config::PoseScheduleConfig& schedule, PoseCallback cb) {
    schedule_ = schedule;
    on_pose_ = std::move(cb);
  }
  // Any thread: a new spindle-speed advice for modbus.robot.advice_register (the robot thread writes it
  // at its next poll; a failed write is tried again). found false: no stable speed in the range.
  void publish_advice(std::uint64_t seq, bool found, double rpm, double margin);
  // Any thread: advice seq withdrawn (status 3: the state it was for is gone before the spindle followed).
  void withdraw_advice(std::uint64_t seq);
  // Any thread: the axial depth the robot cuts (modbus.robot.depth_register), mm; NaN: no register, no
  // poll yet, not available (65535) or the link lost for link_timeout_s.
  [[nodiscard]] double depth_mm() const { return depth_mm_.load(); }
  // The joint angles of the last successful poll, deg (empty before one and after the link is lost for
  // link_timeout_s; NaN where not available).
  [[nodiscard]] std::vector<double> joints_deg() const;

  void start();
  // Writes the enable coil off when it can, then joins the threads.
  void stop();

  // Real-time side: atomics only.
  void request_amplifier_enable(bool on) noexcept override;
  [[nodiscard]] rt::AmplifierStatus amplifier_status() noexcept override;

  // Any thread.
  [[nodiscard]] ModbusCounters counters() const;
  [[nodiscard]] bool amplifier_link_up() const { return amp_up_.load(); }
  [[nodiscard]] bool robot_link_up() const { return robot_up_.load(); }
  [[nodiscard]] config::Mounting mounting() const { return static_cast<config::Mounting>(mounting_.load()); }
  // Blocks until the first successful amplifier poll or the timeout; true when it came.
  bool wait_for_amplifier(std::chrono::duration<double> timeout) const;

 private:
  void amplifier_thread(std::stop_token stop);
  void robot_thread(std::stop_token stop);
  // The spindle register's settling (robot thread only).
  struct SpindleWatch {
    int candidate{-1}, same{0};
    double rpm{0.0};
    bool parked{false};
    std::chrono::steady_clock::time_point last_ok{std::chrono::steady_clock::now()};
  };
  bool poll_spindle(modbus_t* ctx, SpindleWatch& w);  // false: the read failed
  void park_spindle_if_lost(SpindleWatch& w);
  // The joint registers' settling (robot thread only). Region -1: out of the map; -2: nothing yet.
  struct PoseWatch {
    config::PoseSettling settling;
    bool lost{false};
    std::chrono::steady_clock::time_point last_ok{std::chrono::steady_clock::now()};
  };
  bool poll_pose(modbus_t* ctx, PoseWatch& w);  // false: the read failed
  void pose_unknown_if_lost(PoseWatch& w);
  void report_pose(long region);
  bool write_advice(modbus_t* ctx);  // the pending advice, if any; false: the write failed
  bool poll_depth(modbus_t* ctx);    // false: the read failed

  config::ModbusConfig cfg_;
  MountingCallback on_mounting_;
  SpindleCallback on_spindle_;
  std::optional<config::PoseScheduleConfig> schedule_;
  PoseCallback on_pose_;
  std::vector<double> joints_deg_;              // guarded by m_
  std::array<std::uint16_t, 4> advice_regs_{};  // guarded by m_
  bool advice_pending_{false};                  // guarded by m_
  std::atomic<std::uint64_t> advice_writes_{0}, depth_changes_{0}, depth_unavailable_polls_{0};
  std::atomic<double> depth_mm_{std::numeric_limits<double>::quiet_NaN()};
  ModbusLink amp_link_;
  std::optional<ModbusLink> robot_link_;
  mutable std::mutex m_;
  mutable std::condition_variable amp_seen_;  // a good amplifier poll, or stop (wait_for_amplifier)
  bool running_{false};                       // guarded by m_: between start() and stop()

  std::atomic<bool> requested_{false};
  std::atomic<bool> enabled_{false}, ready_{false}, fault_{false};
  std::atomic<double> temperature_c_{0.0};
  std::atomic<std::int64_t> last_ok_ns_{-1};  // CLOCK_MONOTONIC of the last good amplifier poll
  std::atomic<bool> amp_up_{false}, robot_up_{false};
  std::atomic<bool> link_fault_{false};
  std::atomic<int> mounting_;
  std::atomic<std::uint64_t> amp_polls_{0}, robot_polls_{0}, link_faults_{0}, coil_writes_{0}, mounting_changes_{0},
      mounting_unknown_{0}, spindle_changes_{0}, spindle_link_parks_{0}, pose_changes_{0}, pose_out_of_map_polls_{0},
      pose_unavailable_polls_{0}, pose_link_losses_{0};
  std::int64_t link_timeout_ns_;
  threads::Worker amp_, robot_;  // the two pollers (last: stopped before what they use goes)
};

}  // namespace robodamp::drivers
