// Live stability at the current cut (docs/harmonic_notch.md, "Live stability"): the open-loop and damped
// limiting depths of a milling job by the accurate method (milling/accurate_stability.hpp: SDM open loop,
// the sampled loop's SDM damped; the zero-order method, labelled, only where the sampled loop cannot step
// the speed) at the spindle speed the cell runs now, with the active
// parameter set at its gain now and the harmonic notches at that speed in the loop. Computed on a worker
// thread of its own and cached per (speed, parameter set, gain); lookup() never waits for a computation,
// so the telemetry drain and the DDS status thread can ask at their own rate. Off the real-time path.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "config/config.hpp"
#include "config/milling_config.hpp"

namespace robodamp::milling {

struct LiveLimits {
  double rpm{0.0};
  double analysed_rpm{0.0};    // the damped limit's speed: a whole number of loop periods per tooth period
  double open_mm{0.0};         // limit of the open-loop structure at rpm (+inf: none below 1 m)
  double damped_mm{0.0};       // with the loop closed at the set and gain, notches at rpm
  double open_chatter_hz{0.0}, damped_chatter_hz{0.0};
  bool damped_valid{true};     // false: the loop is unstable there (no damped FRF); damped_mm is 0
  std::string problem;         // why damped_valid is false
  std::string method;          // of the damped limit: "sampled-loop SDM", or "zero-order preview" above its speeds
  std::string open_method;     // of the open limit: "SDM"
};

struct LiveStabilitySettings {
  double rpm_step{1.0};        // speeds are rounded to this for the cache
  double gain_step_ns_per_m{10.0};
  std::size_t cache_entries{4096};
};

class LiveStability {
 public:
  // job: tool, material, cut (its axial depth is the job's depth) and the structure named `structure`
  // (empty: the job's own), whose controller parts take the cell's loop; sets: the cell's parameter sets,
  // index 0 the configuration's own. Throws config::ConfigError when the job does not fit the cell (no
  // controller part, structure not found).
  LiveStability(config::MillingConfig job, const std::string& structure, std::vector<config::Config> sets,
                LiveStabilitySettings s = {});
  ~LiveStability();
  LiveStability(const LiveStability&) = delete;
  LiveStability& operator=(const LiveStability&) = delete;

  // Any non-real-time thread, never blocks on a computation: the cached limits for this state, or nothing
  // yet (the request is queued; the newest request replaces an older one not yet started).
  [[nodiscard]] std::optional<LiveLimits> lookup(double rpm, std::size_t set, double gain_ns_per_m);
  // Blocking, for tests and the command line: computes (or finds) the limits.
  [[nodiscard]] LiveLimits compute(double rpm, std::size_t set, double gain_ns_per_m);

  // Low priority (the live lobes): a thread of its own below the cell's others (nice 10) computes these speeds
  // for (set, gain) into the cache; a new sweep replaces the one before. Any thread.
  void sweep(std::size_t set, double gain_ns_per_m, const std::vector<double>& rpm);
  // Any thread: every limit computed so far for (set, gain), by speed.
  [[nodiscard]] std::vector<LiveLimits> known(std::size_t set, double gain_ns_per_m) const;
  // The same for a speed schedule (controller.speed_schedule): each speed with the set and K it runs there.
  struct SweepPoint {
    double rpm{0.0};
    std::size_t set{0};
    double gain_ns_per_m{0.0};
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
  using Key = std::tuple<long, std::size_t, long>;
  [[nodiscard]] Key key(double rpm, std::size_t set, double gain) const;
  [[nodiscard]] LiveLimits evaluate(const Key& k) const;
  [[nodiscard]] LiveLimits evaluate_reported(const Key& k) const;  // a failure as a result with its problem
  void store(const Key& k, LiveLimits l);                          // under m_
  void worker();
  void sweeper();

  config::MillingConfig job_;
  config::StructureConfig structure_;
  std::vector<config::Config> sets_;
  LiveStabilitySettings s_;

  mutable std::mutex m_;
  std::condition_variable cv_;
  std::map<Key, LiveLimits> cache_;
  std::optional<Key> wanted_;
  std::deque<Key> sweep_;
  bool stop_{false};
  std::uint64_t computations_{0};
  std::thread thread_;
  std::thread sweep_thread_;  // last: started after everything it reads
};

}  // namespace robodamp::milling
