// The one stability verdict robodamp promises depths from (docs/milling.md, "Which method makes a depth"):
// semi-discretization of what runs. The open-loop structure by first-order SDM (milling/sdm.hpp); with a
// controller part closed (a damped structure), by the sampled loop's semi-discretization
// (milling/sampled_sdm.hpp). The zero-order method (milling/lobes.hpp) is only a preview or a first guess.
// Off the real-time path.
#pragma once

#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/milling_config.hpp"
#include "milling/sampled_sdm.hpp"
#include "milling/sdm.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

class AccurateStability {
 public:
  // Throws std::invalid_argument for a structure this cannot model (controller parts of different loop
  // rates) and config::ConfigError-free: the job is already checked.
  AccurateStability(const Structure& structure, const config::MillingConfig& job);
  AccurateStability(const Structure& structure, const config::MillingConfig& job, const config::CutConfig& cut);

  // "sampled-loop SDM" (damped) or "SDM" (open loop).
  [[nodiscard]] const std::string& method() const { return method_; }
  [[nodiscard]] bool sampled() const { return sampled_ != nullptr; }
  // The speed the verdict is for (the damped loop: a whole number of loop periods per tooth period).
  [[nodiscard]] double stepped_rpm(double rpm) const { return sampled_ ? sampled_->stepped_rpm(rpm) : rpm; }
  // The highest speed it can analyse (infinite open loop).
  [[nodiscard]] double max_rpm() const;
  // Why it cannot analyse this speed (value, unit and range), or nothing.
  [[nodiscard]] std::optional<std::string> speed_problem(double rpm) const;
  // Grid points per tooth period (open loop: the SDM's steps).
  [[nodiscard]] int grid_per_period() const { return grid_; }

  // Critical depth at one speed: the shallowest depth where the cut loses stability. The search from the
  // first guess (e.g. the zero-order limit) finds one crossing of |mu| = 1; |mu| can cross it more than once
  // with depth (just above a lobe's cusp a flip lobe makes the cut unstable in a window below depths that are
  // stable again), so the depths from floor_mm() up to that crossing are probed in steps of 1.2, each local
  // peak of |mu| between probes searched for a window, and the first unstable one searched down from.
  // Throws std::invalid_argument for a speed out of range.
  [[nodiscard]] SdmPoint critical(double rpm, double guess_mm, double rel_tol = 1e-3) const;
  // The same at many speeds on `threads` threads (0: one per core); same result for any thread count.
  // A list of three or more speeds in increasing order (a diagram) is not probed from the floor at each
  // speed: one search per speed, then wherever a speed's depth is above a neighbour's, the depths from the
  // neighbour's up are probed as above, again where a depth dropped, until none does (at most 8 rounds).
  // progress (optional) is called after each speed with the number done, from one thread at a time.
  [[nodiscard]] std::vector<SdmPoint> critical(const std::vector<double>& rpm, const std::vector<double>& guess_mm,
                                               std::size_t threads = 0, double rel_tol = 1e-3,
                                               const std::function<void(std::size_t)>& progress = {}) const;
  // A diagram (three or more speeds in increasing order on a fine grid; otherwise the same as critical() on the
  // list): the same search and neighbours' rounds, but each speed's first guess is its own times the ratio of
  // answer to guess the speed before it found (the accurate and the zero-order limits drift slowly along the
  // speeds), bracketed from a first step of 1.1 (milling/sdm.hpp). Speeds in runs of 10, each run in order on
  // one thread: the same answer on any number of threads. Each depth within rel_tol of a crossing as
  // critical()'s, found in about a quarter fewer monodromy matrices (docs/milling.md "How fast").
  [[nodiscard]] std::vector<SdmPoint> diagram(const std::vector<double>& rpm, const std::vector<double>& guess_mm,
                                              std::size_t threads = 0, double rel_tol = 1e-3,
                                              const std::function<void(std::size_t)>& progress = {}) const;
  // The dominant multiplier at this depth and speed, and whether it is inside the unit circle.
  [[nodiscard]] std::complex<double> multiplier(double axial_mm, double rpm) const;
  [[nodiscard]] bool stable(double axial_mm, double rpm) const { return std::abs(multiplier(axial_mm, rpm)) < 1.0; }
  // The same at many speeds on `threads` threads (0: one per core); every speed must be analysable.
  [[nodiscard]] std::vector<bool> stable(double axial_mm, const std::vector<double>& rpm,
                                         std::size_t threads = 0) const;
  // Where a single speed's probes start: half the zero-order method's lowest limit at any chatter frequency
  // (flip windows start above it on every job robodamp ships and tests; docs/milling.md).
  [[nodiscard]] double floor_mm() const { return floor_mm_; }

 private:
  // One speed's model, kept across its search and its probes (the sampled loop's system and propagators).
  class Speed;
  // One crossing of |mu| = 1 from the guess (bracketed in steps of 1.6, then Illinois; milling/sdm.hpp).
  [[nodiscard]] SdmPoint search(Speed& at, double guess_mm, double rel_tol, double first_step = kBracketStep) const;
  // The shallowest crossing below `p` (a search's answer at the speed) from probes starting at from_mm; p if none.
  [[nodiscard]] SdmPoint below(Speed& at, const SdmPoint& p, double from_mm, double rel_tol) const;
  // The first depth in [from_mm, to_mm) found unstable by the probes and their peaks' searches, or nothing.
  [[nodiscard]] static std::optional<double> first_unstable(Speed& at, double from_mm, double to_mm);
  // A diagram's rounds: each depth above a neighbour's probed from the neighbour's (critical(), above).
  void below_neighbours(const std::vector<double>& rpm, std::vector<SdmPoint>& out, std::size_t threads,
                        double rel_tol) const;

  std::string method_;
  double floor_mm_{0.0};
  int grid_{0};
  int teeth_{1};
  std::unique_ptr<SdmModel> open_;
  std::unique_ptr<SampledSdm> sampled_;
};

// The whole diagram by the accurate method: the critical depth at time_domain.sdm_points speeds over the
// job's lobes range (those the method can step; the sampled loop stops at max_rpm()), each from the
// zero-order limit there as the first guess, on `threads` threads (0: one per core).
struct AccurateDiagram {
  std::string method;  // AccurateStability::method()
  int grid_per_period{0};
  std::vector<SdmPoint> curve;     // by speed
  SdmPoint minimum;                // the curve's shallowest point (critical_depth_mm infinite if none)
  std::size_t speeds_left_out{0};  // above the method's highest speed
  double max_rpm{0.0};
};
[[nodiscard]] AccurateDiagram accurate_diagram(
    const Structure& structure, const config::MillingConfig& job, std::size_t threads = 0,
    const std::function<void(std::size_t done, std::size_t of)>& progress = {});

}  // namespace robodamp::milling
