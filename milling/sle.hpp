// Surface location error by the frequency-domain method of Schmitz and Mann (docs/physics.md §3).
// The cutting force over one tooth period as a Fourier series (exact per axial slice, helix lag
// included), times the cutter-frame FRF at each harmonic of the tooth-passing frequency, gives the
// steady tool deflection; sampled when each slice's edge is at the surface-generating angle (exit for
// down milling, entry for up milling) it is the wall's error at that height. Positive = undercut (the
// tool deflected away from the wall). Assumes a stable cut. Off the real-time path.
#pragma once

#include <vector>

#include "config/milling_config.hpp"
#include "milling/cutting.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

struct SleResult {
  double rpm{0.0};
  double sle_um{0.0};               // mean over the engaged axial depth
  double min_um{0.0}, max_um{0.0};  // across the depth
  std::vector<double> profile_um;   // per axial slice, tip first
  double mean_normal_force_n{0.0};  // static force towards the wall normal (+y of the cutter frame)
};

[[nodiscard]] SleResult surface_location_error(const Structure& structure, const Cutter& cutter,
                                               const config::MaterialConfig& material, const CutConditions& cut,
                                               config::Axis feed_axis, double rpm, int axial_slices, int harmonics);

// Iterative compensation of the commanded radial depth (docs/physics.md §3): the wall's error with a
// command a_c is e = SLE(a_c) + offset - (a_c - a_target); a_c += e until |e| < tolerance.
struct Compensation {
  double radial_mm{0.0};
  double residual_um{0.0};
  int iterations{0};
  bool converged{false};
  std::vector<double> error_um;  // per iteration, the first with the uncompensated command
};
[[nodiscard]] Compensation compensate(const Structure& structure, const Cutter& cutter,
                                      const config::MaterialConfig& material, const CutConditions& cut,
                                      config::Axis feed_axis, double rpm, double path_offset_um,
                                      const config::SleConfig& settings);

}  // namespace robodamp::milling
