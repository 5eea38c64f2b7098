// Live stability at the current cut (docs/harmonic_notch.md, "Live stability"): the open-loop and damped
// limiting depths of a milling job by the accurate method (milling/accurate_stability.hpp: SDM open loop,
// the sampled loop's SDM damped; the zero-order method, labelled, only where the sampled loop cannot step
// the speed) at the spindle speed the cell runs now, with the active
// parameter set at its gain now and the harmonic notches at that speed in the loop. Computed on a worker
// thread of its own and cached per (speed, parameter set, gain, pose); lookup() never waits for a computation,
// so the telemetry drain and the DDS status thread can ask at their own rate.
// A pose-scheduled cell (PoseDynamics, docs/pose_dynamics.md, "Live stability at the pose"): the limits are
// for the robot at its pose now, rounded to a grid of pose_step_deg: the open limit the robot model's whole
// receptance there, the damped one the robot through the cell's loop (milling::robot_through_cell) whose plant
// is the model's lowest modes at the pose in its plane (analysis::config_in_plane_at_pose), believed where
// that plant's open limit agrees with the whole model's.
// Off the real-time path.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <stop_token>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "config/robot_model_config.hpp"
#include "threads/worker.hpp"

namespace robodamp::milling {

struct LiveLimits {
  double rpm{0.0};
  double analysed_rpm{0.0};  // the damped limit's speed: a whole number of loop periods per tooth period
  double open_mm{0.0};       // limit of the open-loop structure at rpm (+inf: none below 1 m)
  double damped_mm{0.0};     // with the loop closed at the set and gain, notches at rpm
  double open_chatter_hz{0.0}, damped_chatter_hz{0.0};
  bool damped_valid{true};       // false: the loop is unstable there (no damped FRF); damped_mm is 0
  std::string problem;           // why damped_valid is false
  std::string method;            // of the damped limit: "sampled-loop SDM", or "zero-order preview" above its speeds
  std::string open_method;       // of the open limit: "SDM"
  std::vector<double> pose_deg;  // the pose grid's point the limits are for (empty: no pose: the sets' own plants)
  // At a pose: the open limit is the robot model's whole receptance's (every mode of the chain, both
  // directions); the damped one comes from the loop's plant (the model's lowest pose_schedule.modes modes in
  // its plane), trusted where that plant's open limit (loop_open_mm) agrees with the whole model's within
  // LiveStabilitySettings::loop_model_tolerance. Where it does not, the damper's effect is not claimed:
  // damped_mm is the open limit and problem says why.
  double loop_open_mm{0.0};
  bool loop_model_verified{true};
};

// Limits as a cell met them (the run summary's trail along the robot's path): when, for which set and K.
struct LiveLimitsRecord {
  double time_s{0.0};  // loop time of the view that found them
  std::size_t set{0};
  double gain_ns_per_m{0.0};
  LiveLimits limits;
};

// The robot model a pose-scheduled cell's sets are designed on (pose_schedule: model, axis, modes).
struct PoseDynamics {
  std::string model_path;  // the model's file (a pose part of the structure at the pose)
  config::RobotModelConfig model;
  int axis{1};   // the actuator's direction in the model's plane: 0 = x, 1 = y
  int modes{3};  // the model's lowest modes in the loop's plant
};

struct LiveStabilitySettings {
  double rpm_step{1.0};  // speeds are rounded to this for the cache
  double gain_step_ns_per_m{10.0};
  double pose_step_deg{2.0};          // joint angles are rounded to this (PoseDynamics)
  double loop_model_tolerance{0.10};  // the loop's plant's open limit against the whole model's (PoseDynamics)
  std::size_t cache_entries{4096};
};

class LiveStability {
 public:
  // job: tool, material, cut (its axial depth is the job's depth) and the structure named `structure`
  // (empty: the job's own), whose controller parts take the cell's loop; sets: the cell's parameter sets,
  // index 0 the configuration's own. Throws config::ConfigError when the job does not fit the cell (no
  // controller part, structure not found). With pose: the structure's robot is the cell's at the pose asked for
  // (its pose and controller parts are replaced; the job needs neither).
  LiveStability(config::MillingConfig job, const std::string& structure, std::vector<config::Config> sets,
                LiveStabilitySettings s = {}, std::optional<PoseDynamics> pose = std::nullopt);
  ~LiveStability();
  LiveStability(const LiveStability&) = delete;
  LiveStability& operator=(const LiveStability&) = delete;

  // Any non-real-time thread, never blocks on a computation: the cached limits for this state, or nothing
  // yet (the request is queued; the newest request replaces an older one not yet started). pose_deg: the
  // robot's joints now (ignored without PoseDynamics; empty: not known).
  [[nodiscard]] std::optional<LiveLimits> lookup(double rpm, std::size_t set, double gain_ns_per_m,
                                                 const std::vector<double>& pose_deg = {});
  // Blocking, for tests and the command line: computes (or finds) the limits. Throws config::ConfigError for
  // a pose outside the model's travel.
  [[nodiscard]] LiveLimits compute(double rpm, std::size_t set, double gain_ns_per_m,
                                   const std::vector<double>& pose_deg = {});
  // The grid point the limits at pose_deg are for (empty without PoseDynamics or a pose).
  [[nodiscard]] std::vector<double> grid_pose(const std::vector<double>& pose_deg) const;
  // Set `set`'s configuration with its plant at the pose (the set as it is without one).
  [[nodiscard]] config::Config loop_config(std::size_t set, const std::vector<double>& pose_deg) const;
  [[nodiscard]] bool pose_dependent() const { return pose_.has_value(); }

  // Low priority (the live lobes): a thread of its own below the cell's others (nice 10) computes these speeds
  // for (set, gain, pose) into the cache; a new sweep replaces the one before. Any thread.
  void sweep(std::size_t set, double gain_ns_per_m, const std::vector<double>& rpm,
             const std::vector<double>& pose_deg = {});
  // Any thread: every limit computed so far for (set, gain, pose), by speed.
  [[nodiscard]] std::vector<LiveLimits> known(std::size_t set, double gain_ns_per_m,
                                              const std::vector<double>& pose_deg = {}) const;
  // The same for a speed schedule (controller.speed_schedule): each speed with the set and K it runs there.
  struct SweepPoint {
    double rpm{0.0};
    std::size_t set{0};
    double gain_ns_per_m{0.0};
    std::vector<double> pose_deg{};
  };
  void sweep(const std::vector<SweepPoint>& points);
  // Any thread: the limits computed so far of these points, in their order.
  [[nodiscard]] std::vector<LiveLimits> known(const std::vector<SweepPoint>& points) const;

  [[nodiscard]] double depth_mm() const { return job_.cut.axial_mm; }
  [[nodiscard]] const config::MillingConfig& job() const { return job_; }
  [[nodiscard]] const config::StructureConfig& structure() const { return structure_; }
  [[nodiscard]] const std::vector<config::Config>& sets() const { return sets_; }
  [[nodiscard]] std::uint64_t computations() const;

 private:
  struct Key {
    long rpm{0};
    std::size_t set{0};
    long gain{0};
    std::vector<long> pose;  // in pose steps (empty: no pose)
    auto operator<=>(const Key&) const = default;
  };
  [[nodiscard]] Key key(double rpm, std::size_t set, double gain, const std::vector<double>& pose_deg) const;
  [[nodiscard]] std::vector<double> pose_of(const Key& k) const;
  [[nodiscard]] LiveLimits evaluate(const Key& k) const;
  [[nodiscard]] LiveLimits evaluate_loop(const Key& k) const;      // through the loop's plant at the key's pose
  void check_loop_model(LiveLimits& l, bool damping) const;        // at a pose: the whole model's open limit
  [[nodiscard]] LiveLimits evaluate_reported(const Key& k) const;  // a failure as a result with its problem
  void store(const Key& k, LiveLimits l);                          // under m_
  void worker(std::stop_token stop);
  void sweeper(std::stop_token stop);

  config::MillingConfig job_;
  config::StructureConfig structure_;
  config::StructureConfig job_structure_;    // as the job gives it (PoseDynamics: its modal parts are kept)
  config::StructureConfig plane_structure_;  // PoseDynamics at a pose: the robot through the loop in its plane
  std::vector<config::Config> sets_;
  LiveStabilitySettings s_;
  std::optional<PoseDynamics> pose_;

  mutable std::mutex m_;
  std::map<Key, LiveLimits> cache_;
  std::optional<Key> wanted_;
  std::deque<Key> sweep_;
  std::uint64_t computations_{0};
  threads::Worker worker_;   // the limits asked for now (lookup)
  threads::Worker sweeper_;  // last: started after everything it reads; the sweep's speeds, at low priority
};

}  // namespace robodamp::milling
