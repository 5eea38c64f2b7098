// The lobe and SLE studies behind `robodamp lobes` and `robodamp sle` (docs/milling.md), as plain results:
// the zero-order preview or the accurate method (semi-discretization of what runs) over the job's speeds
// with the direct test at chosen speeds, and the SLE map and test conditions with each cut's stability by
// the accurate method. apps/ formats them as text, JSON and plots. Off the real-time path.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config/milling_config.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

// What the zero-order method's depths are: a fast preview, never a promise.
inline constexpr const char* kZeroOrderPreview = "zero-order preview";

struct LobeCurvePoint {
  double rpm{0.0};
  double b_lim_mm{0.0};              // +inf or NaN: no limit at this speed
  std::optional<double> chatter_hz;  // none where the preview has no limit
  std::optional<int> lobe;           // the zero-order preview's lobe number
  std::optional<std::string> type;   // the accurate method's loss of stability (hopf, flip)
};

struct LobeAtSpeed {
  double rpm{0.0};                      // the accurate method steps the speed to the loop rate
  std::optional<double> requested_rpm;  // the accurate method: the speed asked for
  double b_lim_mm{0.0};
  std::optional<double> b_lim_lobes_mm;  // the zero-order lobes' limit there
  std::optional<double> chatter_hz;
  std::optional<int> lobe;          // the zero-order preview
  std::optional<std::string> type;  // the accurate method
};

struct LobeStudy {
  std::string structure;
  bool closed_loop{false};
  std::string method;  // kZeroOrderPreview or the accurate method's name
  bool accurate{false};
  int steps_per_period{0};          // the accurate method's grid
  std::size_t frequency_points{0};  // the preview's chatter frequencies
  std::vector<LobeCurvePoint> curve;
  double min_b_lim_mm{0.0}, min_rpm{0.0}, min_chatter_hz{0.0};
  std::vector<LobeAtSpeed> at_rpm;  // the direct test at the requested speeds, in order
  double diagram_ms{0.0};           // wall time of the study
  std::vector<std::string> notes;
};

// The zero-order preview's diagram over the job's lobes range and its direct test at `rpms`.
[[nodiscard]] LobeStudy zero_order_lobe_study(const Structure& structure, const config::MillingConfig& cfg,
                                              const std::vector<double>& rpms);
// The accurate method's diagram at time_domain.sdm_points speeds over the lobes range (those it can step)
// and its critical depth at `rpms`, each from the zero-order limit as the first guess. progress(method,
// done, of, seconds) is called as the speeds finish. Throws config::ConfigError naming --rpm for a speed it cannot step.
[[nodiscard]] LobeStudy accurate_lobe_study(
    const Structure& structure, const config::MillingConfig& cfg, const std::vector<double>& rpms,
    const std::function<void(const std::string& method, std::size_t done, std::size_t of, double s)>& progress);

struct SleMapPoint {
  double rpm{0.0};
  double sle_um{0.0}, sle_min_um{0.0}, sle_max_um{0.0};
  double b_lim_preview_mm{0.0};  // the zero-order preview's limit there (+inf: none)
  bool stable{true};             // the configured depth at this speed
  std::string stability_method;
};

struct SleCondition {
  std::string name;
  double rpm{0.0}, axial_mm{0.0}, radial_mm{0.0}, ft_mm{0.0};
  config::Axis surface_normal{config::Axis::kY};
  double sle_um{0.0};          // with the measured path offset
  double sle_dynamic_um{0.0};  // the structure's part alone
  double path_offset_um{0.0};
  double sle_min_um{0.0}, sle_max_um{0.0};
  double mean_normal_force_n{0.0};
  double compensated_radial_mm{0.0}, compensation_residual_um{0.0};
  int compensation_iterations{0};
  bool compensation_converged{false};
  bool stable{true};
  std::string stability_method;
};

struct SleStudy {
  std::string structure;
  bool closed_loop{false};
  std::vector<SleMapPoint> map;  // sle.points speeds over the sle range at the configured cut
  int map_unstable_points{0};    // where the configured depth chatters (SLE not meaningful)
  int map_preview_points{0};     // above the accurate method's highest speed: the preview decides
  std::string stability_method;
  std::vector<SleCondition> conditions;  // each test condition at each surface normal
  std::vector<std::string> notes;
};

[[nodiscard]] SleStudy sle_study(const Structure& structure, const config::MillingConfig& cfg);

}  // namespace robodamp::milling
