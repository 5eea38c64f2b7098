// The milling process model (docs/physics.md §2-3), in the cutter's frame: x along the feed, y
// along the machined wall's normal, tooth angle phi measured clockwise from +y (Altintas). A tooth at
// phi is at (R sin phi, R cos phi) from the tool axis; it cuts the chip h = ft sin(phi) and feels
//   Ft = kt b h + kte b,  Fr = kr b h + kre b,
//   Fx = -Ft cos(phi) - Fr sin(phi),  Fy = Ft sin(phi) - Fr cos(phi)   (force on the tool).
// Down milling cuts phi in [phi_st, pi] and leaves the wall at phi = pi (y = -R); up milling cuts
// [0, phi_ex] and leaves it at phi = 0 (y = +R). Off the real-time path.
#pragma once

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "config/milling_config.hpp"

namespace robodamp::milling {

using Complex = std::complex<double>;

struct Engagement {
  double start_rad{0.0};
  double exit_rad{0.0};
  [[nodiscard]] double width_rad() const { return exit_rad - start_rad; }
};

// Entry and exit angles for a radial depth on a cutter of this radius (radial >= 2 R: slotting).
[[nodiscard]] Engagement engagement(double radius_mm, double radial_mm, config::MillingMode mode);
// Angle at which the finished wall is generated: exit for down milling, entry for up milling.
[[nodiscard]] double surface_angle_rad(config::MillingMode mode);

// Zero-order directional matrix [alpha] (docs/physics.md §2), each term evaluated between entry and
// exit, Kr = kr / kt. The mean periodic force is (N kt b / 4 pi) [alpha] {delta}.
[[nodiscard]] Eigen::Matrix2d directional_matrix(const Engagement& e, double kr_over_kt);

// The process for one cut.
struct Cutter {
  config::ToolKind kind{config::ToolKind::kEndMill};
  double radius_mm{6.35};
  int teeth{3};
  double helix_rad{0.0};
};
[[nodiscard]] Cutter cutter_from(const config::ToolConfig& tool);

struct CutConditions {
  config::MillingMode mode{config::MillingMode::kDown};
  double radial_mm{1.0};
  double axial_mm{1.0};
  double feed_per_tooth_mm{0.1};
};

// Fourier coefficients of the total force on the tool over one tooth period, per harmonic k = 0..K of
// the tooth-passing frequency, phase referred to tooth 1's bottom edge at phi = 0 (t = phi / Omega).
// Exact integrals of the piecewise trigonometric force over each axial slice's engagement (no sampling,
// so entry and exit discontinuities do not alias). Units: N.
struct ForceSpectrum {
  std::vector<Complex> fx;  // [k]
  std::vector<Complex> fy;
};
[[nodiscard]] ForceSpectrum force_spectrum(const Cutter& cutter, const config::MaterialConfig& material,
                                           const CutConditions& cut, int axial_slices, int harmonics);

// Axial slice geometry: height above the tool tip, local radius, axial immersion angle (pi/2 on the
// cylinder, less on a ball end's sphere) and the helix lag of the slice's edge behind the tip.
struct Slice {
  double z_mm{0.0};
  double height_mm{0.0};
  double radius_mm{0.0};
  double kappa_rad{0.0};
  double lag_rad{0.0};
};
[[nodiscard]] std::vector<Slice> slices(const Cutter& cutter, double axial_mm, int count);
// A slice's own radial depth of cut: the wall's edge is at R - radial from the axis on the engaged side,
// so a slice of smaller radius (a ball end's) engages only what lies beyond it; <= 0: the slice is not in
// the cut. The one rule the force spectrum, the SDM, the time-domain cut and the SLE use.
[[nodiscard]] inline double slice_radial_mm(const Cutter& cutter, const Slice& s, double radial_mm) {
  return radial_mm - (cutter.radius_mm - s.radius_mm);
}

}  // namespace robodamp::milling
