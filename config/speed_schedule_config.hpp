// The controller scheduled by spindle speed (docs/tuning.md, "A controller that follows the spindle"):
// bands of spindle speed, each with the controller and the K the accurate stability method found deepest
// there (K = 0 included, where the damper would lower the limit). `robodamp schedule` writes it. The loop
// follows the spindle speed it has (Modbus, DDS, --spindle-rpm): K ramps over controller.gain_ramp_s when
// the band changes, and another band's controller is handed over (fade out, swap, fade in). Outside every
// band (the spindle stopped, or beyond the bands) the configuration's own controller runs at
// controller.gain_ns_per_m. Self-contained: the other controllers are written in the file, as the
// compensator block and polarity that replace the chain's own (the rest of the chain is shared).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "config/number_range.hpp"

namespace robodamp::config {

struct BlockConfig;

struct SpeedBandConfig {
  double rpm_min{0.0}, rpm_max{0.0};  // [rpm_min, rpm_max): ascending and disjoint across the bands
  int controller{0};                  // 0: this configuration's; i: speed_schedule.controllers[i - 1]
  double gain_ns_per_m{0.0};
  // The deepest cut the band vouches for at any of its speeds, where the accurate method's limit is deeper than
  // the cut in time holds (robodamp schedule checks every limit in time): the limits the cell publishes, the
  // lobes and the cut's verdict take the smaller of the two. None: the accurate method's limit.
  std::optional<double> depth_limit_mm;
};

// Another controller a band may run: this configuration's chain with its compensator block replaced.
struct SpeedControllerConfig {
  std::vector<BlockConfig>
      compensator;  // exactly one block, kind compensator (a vector: BlockConfig is declared later)
  int polarity{1};
  std::optional<double> match_freq_hz;  // default the configuration's
};

struct SpeedScheduleConfig {
  std::vector<SpeedControllerConfig> controllers;
  std::vector<SpeedBandConfig> bands;
};

// At most this many bands and controllers (the real-time controller holds them in fixed arrays).
inline constexpr std::size_t kMaxSpeedBands = 64;
inline constexpr std::size_t kMaxSpeedControllers = 8;

struct Config;
// The configuration a band's controller i runs as (i >= 1): this one with speed_schedule.controllers[i - 1]'s
// compensator block, polarity and match frequency, the schedule itself kept and K 0 outside the bands (there
// set 0 runs).
[[nodiscard]] Config speed_controller_config(const Config& cell, std::size_t i);
// The same controller as an entry of the schedule: other's compensator block, polarity and match frequency.
// Throws ConfigError naming other's file when its chain has no compensator.
[[nodiscard]] SpeedControllerConfig speed_controller_of(const Config& other);
// cell with the controller's compensator, polarity and match frequency.
[[nodiscard]] Config with_speed_controller(const Config& cell, const SpeedControllerConfig& c);

// The K parameter set `set` of a cell runs at this spindle speed (set_cfg: that set's configuration; the
// cell's own is set 0, a band's controller i is set i): without a schedule controller.gain_ns_per_m; in a band
// its K when the band names this set (a schedule of K alone names every set's own), 0 when it names another;
// outside every band the set's controller.gain_ns_per_m (0 on a band's controller: set 0 runs there).
[[nodiscard]] double scheduled_gain_ns_per_m(const Config& set_cfg, std::size_t set, double rpm);
// The set that runs at this speed when `set` (configured by set_cfg) is active: a band's controller, set 0
// outside every band of a schedule that chooses controllers, `set` itself otherwise.
[[nodiscard]] std::size_t scheduled_set(const Config& set_cfg, std::size_t set, double rpm);
// The depth_limit_mm of the band holding rpm where set (configured by set_cfg) runs it at K > 0, or none.
[[nodiscard]] std::optional<double> scheduled_depth_limit_mm(const Config& set_cfg, std::size_t set, double rpm);

// The band holding rpm (rpm_min <= rpm < rpm_max; the last band also holds its rpm_max), or none.
[[nodiscard]] std::optional<std::size_t> speed_band_of(const std::vector<SpeedBandConfig>& bands, double rpm);

}  // namespace robodamp::config
