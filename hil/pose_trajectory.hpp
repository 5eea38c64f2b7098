// The robot moving along a pose trajectory in the HIL emulator (robodamp plant --pose-at T:Q1,Q2,...;
// docs/pose_dynamics.md, "Scheduling by pose"): joint angles over time (linear between waypoints, held
// after the last), written to the robot controller's joint registers, and the plant's modes following
// the robot model at the pose now (pose_schedule's model, axis and mode count), retuned every update
// period. Where two waypoints hold the same pose the robot dwells, and the emulator measures the
// receptance there with an impact campaign of its own, next to the analysis's prediction for that pose.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "analysis/bench_run.hpp"
#include "analysis/modal_test.hpp"

#include "analysis/pose_schedule.hpp"
#include "config/config.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::hil {

struct PoseWaypoint {
  double t_s{0.0};
  std::vector<double> joints_deg;
};

struct PoseDwell {
  double t0_s{0.0}, t1_s{0.0};
  std::vector<double> joints_deg;
};

// What one dwell measured, against the analysis.
struct PoseDwellReport {
  std::vector<double> joints_deg;
  double t0_s{0.0}, t1_s{0.0};
  std::string region;       // the schedule's region for the pose ("" outside every region)
  double dominant_hz{0.0};  // of the robot model at the pose
  int records{0};
  double open_peak_m_per_n{0.0}, closed_peak_m_per_n{0.0}, closed_peak_hz{0.0};
  double improvement_pct{0.0};  // measured: open peak / closed peak - 1
  double predicted_pct{0.0};    // the region's set at this pose (discrete loop)
  double coherence_min{0.0};
};

class PoseTrajectory {
 public:
  // Throws config::ConfigError: no pose_schedule, waypoints out of order, a pose outside the joints' travel.
  PoseTrajectory(const config::Config& cfg, std::vector<PoseWaypoint> points);
  [[nodiscard]] std::vector<double> at(double t_s) const;
  [[nodiscard]] std::vector<PoseDwell> dwells() const;
  // The robot's stops as a controller reading its joints counts them: dwells in a row at one pose are one.
  [[nodiscard]] std::vector<PoseDwell> stops() const;
  [[nodiscard]] const config::Config& config() const { return cfg_; }
  // The plant's structure at a pose (the configuration's actuator, sensor and locations).
  [[nodiscard]] sim::PlantModel plant_at(const std::vector<double>& joints_deg) const;
  // Built before the run (about 0.25 ms each, longer than a loop period): the structure at every multiple
  // of update_s where the pose has moved since the last one, in time order.
  [[nodiscard]] std::vector<std::pair<double, sim::PlantModel>> retunes(double update_s) const;
  // The region's name, the dominant mode and the predicted improvement at a pose.
  void predict(PoseDwellReport& r) const;
  [[nodiscard]] double end_s() const { return points_.back().t_s; }

 private:
  const config::Config& cfg_;
  std::vector<PoseWaypoint> points_;
  analysis::PoseScheduleAnalysis schedule_;
};

// An impact campaign at each dwell of the trajectory (as many bench.record_s records as fit after
// hil.settle_s), on the emulator's plant; at the end, the same hits on an in-process plant at the dwell's
// pose with the amplifier off give each dwell's open-loop reference.
class DwellCampaigns {
 public:
  // Allocates every record now (the realtime pacing never stalls for it).
  DwellCampaigns(const config::Config& cfg, sim::Plant& plant, const PoseTrajectory& trajectory,
                 const analysis::ImpactTest& test);
  void before_step(std::size_t k) noexcept;
  void after_step(std::size_t k) noexcept;
  [[nodiscard]] std::size_t count() const { return campaigns_.size(); }
  [[nodiscard]] std::vector<PoseDwellReport> finish() const;

 private:
  const config::Config& cfg_;
  const PoseTrajectory& trajectory_;
  analysis::ImpactTest test_;
  std::vector<PoseDwell> dwells_;
  std::deque<config::Config> configs_;  // each campaign's (its averages); the campaigns hold references
  std::vector<std::unique_ptr<analysis::ImpactCampaign>> campaigns_;
};

// --measure-out along the trajectory (measure --along-path's plant side): every stop at least as long as a
// stopped measurement's plan (the loop's chirp after commissioning.settle_s, then the hammer at every
// location). Throws config::ConfigError naming the stop, its length and the plan's.
void check_measurement_stops(const PoseTrajectory& t, const analysis::CommissioningPlan& plan);

// "T:Q1,Q2,Q3" (s, deg): one waypoint; nothing (and why in error) when malformed.
[[nodiscard]] bool parse_waypoint(const std::string& item, PoseWaypoint& out, std::string& error);

}  // namespace robodamp::hil
