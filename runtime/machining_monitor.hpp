// The cell's live machining view (docs/harmonic_notch.md, "Live stability"): the spindle speed the loop
// has (from the set_spindle commands in the telemetry frames, whatever sent them: the robot's Modbus
// register or a DDS request), the job's depth, its open-loop and damped limits at that speed from
// milling::LiveStability (worker thread, cached), and the chatter indicator over the control
// accelerometer's recent samples. Fed by the telemetry drain (on_frame), read by the DDS status thread
// and the run summary (sample). Its speed advisor watches the same view (runtime/speed_advisor.hpp).
// Off the real-time path.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "config/config.hpp"
#include "dds/bridge.hpp"
#include "milling/chatter_indicator.hpp"
#include "milling/live_stability.hpp"
#include "rt/telemetry_frame.hpp"
#include "runtime/awaited_states.hpp"
#include "runtime/speed_advisor.hpp"

namespace robodamp::runtime {

// Whether the tool is in the cut, and what says so (dds::kCutting ...), first match:
//   - the spindle stopped: not cutting;
//   - the robot's depth (modbus.robot.depth_register): 0 not cutting, above 0 cutting;
//   - the chatter indicator's window: chatter, or the spindle's forced lines 10 x above the noise, cutting;
//     neither, not cutting (the spindle turning in the air);
//   - otherwise (the window not full yet): not known.
struct Cutting {
  std::uint8_t state{dds::kCuttingUnknown};
  std::string reason;
};
[[nodiscard]] Cutting cutting_state(double spindle_rpm, bool depth_measured, double depth_mm,
                                    const milling::ChatterIndicator& c);

// What the monitor reads of the cell (any thread each, all optional but active_set).
struct MachiningInputs {
  std::function<std::size_t()> active_set;  // the supervisor's running set
  // Whether a parameter-set hand-over is under way (the set selected is not yet the one running; empty: never):
  // the state it would be advised for ends within the hand-over's fade and warm-up.
  std::function<bool()> handing_over;
  std::function<void(const AdviceRecord&)>
      on_advice;  // each new spindle-speed advice and each change of its status, on the advisor's thread
  std::function<double()> robot_depth_mm;  // the robot's depth (0: out of the cut; NaN: the job's)
  // A pose-scheduled cell: the robot's joints now (empty: not known) and the model its sets are designed on;
  // the limits, the live lobes and the advice are then for the robot at that pose (milling::PoseDynamics).
  std::function<std::vector<double>()> pose_deg;
  std::optional<milling::PoseDynamics> pose;
  // The robot program's next poses (dds.path_ahead; empty: none published): the advice checks its
  // candidates there too, with the region's set and K the pose schedule (`schedule`) would run at each.
  std::function<std::vector<std::vector<double>>()> path_ahead_deg;
  std::optional<config::PoseScheduleConfig> schedule;
};

class MachiningMonitor {
 public:
  // cfg: the cell's configuration (spindle.job names the job); sets: every parameter set's configuration
  // (index 0 = cfg). Throws config::ConfigError when the job cannot be read or does not fit.
  MachiningMonitor(const config::Config& cfg, std::vector<config::Config> sets, MachiningInputs in);

  // The drain thread, every frame.
  void on_frame(const rt::TelemetryFrame& f);
  // Any thread: the state now (the limits as far as computed; the indicator evaluated now).
  [[nodiscard]] dds::MachiningSample sample();
  // Blocking: waits (up to timeout_s) for the limits at the current state, then samples (tests, summary).
  [[nodiscard]] dds::MachiningSample settled_sample(double timeout_s);
  // For the run's summary: the limits of every state the robot left before the worker had them (robot faster
  // than the analysis: a lockstep run, a quick move), computed here on the caller's thread until timeout_s,
  // into the trail in the order met. Off the real-time path.
  void complete_trail(double timeout_s);
  [[nodiscard]] milling::LiveStability& stability() { return *stability_; }
  // The status thread: the live lobes at the active set and the gain the loop has held since the last call
  // (a sweep over the job's speed range is asked for on the first call with a settled gain), when more
  // speeds are known than were last returned.
  [[nodiscard]] std::optional<dds::LobesSample> lobes();
  // Any thread: a pose-scheduled cell's limits at each new state met (pose grid point, speed, set, gain), in
  // the order met, the first kTrailEntries (each also logged, one line). A state the robot left before its
  // limits were ready joins when the worker has them (if it had started on them), at the time it was met.
  [[nodiscard]] std::vector<milling::LiveLimitsRecord> trail() const;
  static constexpr std::size_t kTrailEntries = 64;
  // Any thread: the latest spindle-speed advice (runtime/speed_advisor.hpp), if any was asked for.
  [[nodiscard]] std::optional<AdviceRecord> advice() const { return advisor_->latest(); }
  // The job's modes above the live indicator's band (milling::modes_above_band; warned at construction).
  [[nodiscard]] const std::vector<double>& unheard_modes_hz() const { return unheard_modes_hz_; }

 private:
  [[nodiscard]] std::optional<dds::LobesSample> scheduled_lobes(std::size_t active);
  [[nodiscard]] AdviceView view();
  [[nodiscard]] std::pair<std::size_t, double> set_and_gain();  // the active set and the gain its limits are for
  [[nodiscard]] std::vector<double> pose_now() const;           // the robot's joints (empty: not known, no pose)
  void log_chatter(const milling::ChatterIndicator& c);
  void add_to_trail(double time_s, std::size_t set, double gain, const milling::LiveLimits& l);
  // A state met whose limits were not ready: kept until the worker has them, at most kAwaited, the shortest
  // stay dropped first (runtime/awaited_states.hpp).
  void await_limits(double time_s, double rpm, std::size_t set, double gain, const std::vector<double>& pose_deg);
  // The awaited states the robot has left (not `now`) computed since, into the trail in the order met.
  void trail_awaited(const milling::LiveStability::SweepPoint& now);
  static constexpr std::size_t kAwaited = 8;
  // The last limits found when they are for this speed, set and K (at another pose).
  [[nodiscard]] std::optional<milling::LiveLimits> moved_from(double rpm, std::size_t set, double gain) const;
  int teeth_;
  std::vector<double> unheard_modes_hz_;
  std::vector<config::Config> set_configs_;  // every parameter set's configuration (their K by speed)
  std::function<std::size_t()> active_set_;
  std::function<bool()> handing_over_;
  std::function<double()> robot_depth_mm_;
  std::function<std::vector<double>()> pose_deg_;
  std::function<std::vector<std::vector<double>>()> path_ahead_deg_;
  // A measured map's spread at a pose (dds::MachiningSample::mode_spread_pct), the last pose's kept.
  void mode_spread(dds::MachiningSample& s);
  std::optional<milling::PoseDynamics> pose_;
  std::vector<double> spread_pose_;
  double spread_pct_{-1.0}, spread_nearest_deg_{-1.0};
  std::optional<config::PoseScheduleConfig> schedule_;
  std::unique_ptr<milling::LiveStability> stability_;
  mutable std::mutex m_;
  std::vector<milling::LiveLimitsRecord> trail_;     // guarded by m_
  std::optional<milling::LiveLimitsRecord> latest_;  // the last limits found at a pose (guarded by m_)
  std::vector<AwaitedState> awaited_;                // guarded by m_
  milling::ChatterMonitor chatter_;
  bool chatter_logged_{false};  // the last verdict logged
  double next_chatter_log_s_{0.0};
  rt::TelemetryFrame last_{};
  double rpm_{0.0};
  std::vector<double> lobe_rpm_;  // the sweep's speeds
  std::size_t lobes_set_{0};      // the status thread's
  double lobes_gain_{-1.0};
  std::vector<double> lobes_pose_;  // on the stability's grid
  bool lobes_swept_{false};
  bool lobes_scheduled_{false};  // the last lobes were a speed schedule's envelope
  std::size_t lobes_published_{0};
  std::unique_ptr<SpeedAdvisor> advisor_;  // last: its thread reads the members above
};

}  // namespace robodamp::runtime
