// Spindle-speed advice (docs/milling.md, "Spindle-speed advice"): when the cut chatters, or the job's depth
// is above the accurate limit at the speed it runs, the speeds in the allowed range at which that depth is
// stable with margin, nearest the current speed first. Candidates: the stable pockets the measured chatter
// frequency and the structure's modes point to (the tooth-passing frequency at f / k, k = 1, 2, ...: the
// phase between successive cuts then repeats, and the regeneration has nothing to feed on), and a grid
// over the range for the pockets neither names. Each is checked with the accurate method at its own speed
// (milling::LiveStability: SDM open loop, the sampled loop's SDM damped, the harmonic notches at that
// speed), the method it names. Off the real-time path: seconds on a worker thread.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "milling/live_stability.hpp"

namespace robodamp::milling {

struct SpeedAdviceSettings {
  double depth_margin{1.15};  // advised only where the limit is at least this x the depth
  // ... or this x, when the depth is only known to be at least the limit where the cut chatters: a speed
  // just above that limit left the HIL cut ringing at 91 % of its limit (0.95 mm at 758 rpm, damped,
  // scripts/advice_demo.sh), which the live indicator takes for chatter.
  double chatter_depth_margin{1.3};
  std::size_t grid_points{48};  // uniform candidates over the range, beside the pockets
  std::size_t max_options{3};
  std::size_t max_path_poses{6};    // of the path ahead: at most this many poses, evenly along it
  std::function<bool()> cancelled;  // checked between candidates (the cell is shutting down): stop there
};

struct SpeedAdviceRequest {
  double rpm{0.0};       // the speed the cell runs now
  double depth_mm{0.0};  // the job's axial depth
  std::size_t set{0};    // the active parameter set and its gain: the damped limit's loop
  double gain_ns_per_m{0.0};
  // A speed schedule (controller.speed_schedule): the set and K the cell runs at a speed, so that each
  // candidate is judged with the controller it would get there. Empty: set and gain at every speed.
  std::function<std::pair<std::size_t, double>(double rpm)> controller_at{};
  bool damped{true};             // the damper active: the damped limits apply, else the open ones
  double chatter_hz{0.0};        // measured (the chatter indicator's strongest line); 0: none measured
  std::string trigger;           // "chatter", or "depth above the limit"
  std::vector<double> pose_deg;  // the robot's joints (a pose-scheduled cell): every candidate checked at that pose
  // The next part of the path, as the robot program publishes it (dds.path_ahead): every candidate is also
  // checked at these poses, with the set and K that would run at each (controller_at_pose; empty: the
  // current set and K), and its limit is the lowest met. Only with a pose.
  std::vector<std::vector<double>> path_ahead_deg;
  std::function<std::pair<std::size_t, double>(const std::vector<double>& pose_deg, double rpm)> controller_at_pose{};
};

struct SpeedCandidate {
  double rpm{0.0};
  std::string source;  // "chatter frequency", "mode", "grid"
};

struct SpeedOption {
  double rpm{0.0};       // the speed analysed (the damped loop: whole loop periods per tooth period)
  double limit_mm{0.0};  // the accurate limit there (damped or open, as the request); along a path, the lowest
  double margin{0.0};    // limit / depth
  std::string source;
  std::vector<double> limiting_pose_deg;  // where the limit is lowest (the pose now, or one ahead); empty: no pose
};

struct SpeedAdvice {
  SpeedAdviceRequest request;
  double rpm_min{0.0}, rpm_max{0.0};  // the allowed range searched
  double limit_now_mm{0.0};           // at the current speed
  // The depth the margins are against: the request's, or, when chatter is measured at a speed whose limit
  // is above it, that limit (the cut chatters, so it is at least that deep by the model: the depth
  // told is wrong, or the model is optimistic there).
  double depth_mm{0.0};
  bool depth_from_chatter{false};
  std::string method;  // which method made the limits ("sampled-loop SDM", "SDM", ...)
  bool found{false};
  std::vector<SpeedOption> options;  // found: up to max_options, nearest the current speed first
  SpeedOption best;                  // the candidate with the largest margin (also when none qualifies)
  std::string reason;                // not found: why, with the numbers
  std::size_t evaluated{0};          // candidate speeds analysed
  // The poses each candidate was checked at: the pose now, then those of the path ahead (at most
  // max_path_poses of the request's); empty without a pose.
  std::vector<std::vector<double>> poses_checked;
  double compute_s{0.0};  // wall time it took
};

// The candidate speeds in [rpm_min, rpm_max], sorted and without near-duplicates (within 0.5 rpm): the
// pockets of the chatter frequency (if > 0) and of each mode frequency, then the grid.
[[nodiscard]] std::vector<SpeedCandidate> advice_candidates(double rpm_min, double rpm_max, int teeth,
                                                            double chatter_hz, const std::vector<double>& mode_hz,
                                                            std::size_t grid_points);

// At most `count` of the path's poses, evenly along it, its first and last among them.
[[nodiscard]] std::vector<std::vector<double>> thin_path(const std::vector<std::vector<double>>& path,
                                                         std::size_t count);

// The allowed range: the job's lobes range within the spindle's maximum. Throws std::invalid_argument
// (value, unit, range) for a request that cannot be answered (a speed or depth not finite or not positive).
[[nodiscard]] SpeedAdvice advise_speed(LiveStability& stability, const SpeedAdviceRequest& request, double rpm_min,
                                       double rpm_max, const SpeedAdviceSettings& s = {});

}  // namespace robodamp::milling
