// A speed schedule's damped limits checked in time (docs/tuning.md, "Checked in time"): at a speed, a cut at
// a fraction (0.95) of the accurate method's damped limit, with the real Controller on the simulated plant
// (milling::DampedDynamics, the job's revolutions). The linear methods miss what the cut's nonlinearity does:
// a flip whose multiplier sits just inside the unit circle (|mu| 0.97-0.98) decays so slowly that the cut's
// entry transient throws the tool out of the cut, and the cut flips into a large cycle far below the linear
// limit (subcritical; robot C at 272.5 rpm: sampled-loop SDM 1.565 mm, a flip in time from 0.84 mm). Where the
// cut chatters, the limit is the time domain's critical depth there (milling::critical_depth). Off the
// real-time path.
#pragma once

#include <cstddef>
#include <vector>

#include "config/milling_config.hpp"
#include "milling/structure.hpp"

namespace robodamp::tune {

struct LimitInTime {
  double rpm{0.0};                               // as the sampled loop runs it
  const milling::Structure* structure{nullptr};  // with the controller part at its candidate's gain
  double limit_mm{0.0};                          // the accurate method's
};

struct LimitInTimeResult {
  bool held{true};       // the cut at fraction x limit_mm was stable
  double limit_mm{0.0};  // limit_mm where it held; else the time domain's critical depth (at most limit_mm)
  int simulations{0};
};

inline constexpr double kInTimeFraction = 0.95;  // of the limit, as commission's and the tests' cuts in time

// Each check on its own cut(s), on up to `threads` threads (0: one per core); results in the order given.
[[nodiscard]] std::vector<LimitInTimeResult> limits_in_time(const config::MillingConfig& job,
                                                            const std::vector<LimitInTime>& checks, std::size_t threads,
                                                            double fraction = kInTimeFraction);

}  // namespace robodamp::tune
