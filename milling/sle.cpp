#include "milling/sle.hpp"

#include <algorithm>
#include <cmath>

namespace robodamp::milling {

SleResult surface_location_error(const Structure& structure, const Cutter& cutter,
                                 const config::MaterialConfig& material, const CutConditions& cut,
                                 config::Axis feed_axis, double rpm, int axial_slices, int harmonics) {
  const ForceSpectrum f = force_spectrum(cutter, material, cut, axial_slices, harmonics);
  const double tooth_hz = rpm / 60.0 * cutter.teeth;
  // Normal row of the cutter-frame FRF at each harmonic.
  std::vector<Complex> g_nx(f.fx.size()), g_ny(f.fx.size());
  for (std::size_t k = 0; k < f.fx.size(); ++k) {
    const Eigen::Matrix2cd g = structure.frf_cutter(static_cast<double>(k) * tooth_hz, feed_axis);
    g_nx[k] = g(1, 0);
    g_ny[k] = g(1, 1);
  }
  const double phi_surface = surface_angle_rad(cut.mode);
  const double sign = cut.mode == config::MillingMode::kDown ? 1.0 : -1.0;  // away from the wall
  SleResult r;
  r.rpm = rpm;
  r.mean_normal_force_n = f.fy[0].real();
  r.min_um = 1e300;
  r.max_um = -1e300;
  double sum = 0.0;
  for (const Slice& s : slices(cutter, cut.axial_mm, axial_slices)) {
    if (slice_radial_mm(cutter, s, cut.radial_mm) <= 0.0) continue;  // a ball end's tip below the cut
    // The slice's edge is at the surface angle at t = (phi_surface + lag) / Omega: tooth phase N (phi + lag).
    const double phase = cutter.teeth * (phi_surface + s.lag_rad);
    double y_m = (g_nx[0] * f.fx[0] + g_ny[0] * f.fy[0]).real();
    for (std::size_t k = 1; k < f.fx.size(); ++k)
      y_m += 2.0 * ((g_nx[k] * f.fx[k] + g_ny[k] * f.fy[k]) * std::polar(1.0, static_cast<double>(k) * phase)).real();
    const double um = sign * y_m * 1e6;
    r.profile_um.push_back(um);
    r.min_um = std::min(r.min_um, um);
    r.max_um = std::max(r.max_um, um);
    sum += um;
  }
  r.sle_um = r.profile_um.empty() ? 0.0 : sum / static_cast<double>(r.profile_um.size());
  if (r.profile_um.empty()) r.min_um = r.max_um = 0.0;
  return r;
}

Compensation compensate(const Structure& structure, const Cutter& cutter, const config::MaterialConfig& material,
                        const CutConditions& cut, config::Axis feed_axis, double rpm, double path_offset_um,
                        const config::SleConfig& settings) {
  Compensation c;
  CutConditions cmd = cut;
  for (int it = 0; it <= settings.max_iterations; ++it) {
    const double sle = surface_location_error(structure, cutter, material, cmd, feed_axis, rpm, settings.axial_slices,
                                              settings.harmonics)
                           .sle_um;
    const double error = sle + path_offset_um - (cmd.radial_mm - cut.radial_mm) * 1000.0;
    c.error_um.push_back(error);
    c.radial_mm = cmd.radial_mm;
    c.residual_um = error;
    c.iterations = it;
    if (std::abs(error) < settings.tolerance_um) {
      c.converged = true;
      break;
    }
    const double next = std::clamp(cmd.radial_mm + error / 1000.0, 1e-6, 2.0 * cutter.radius_mm);
    if (next == cmd.radial_mm) break;  // at a bound: cannot compensate further
    cmd.radial_mm = next;
  }
  return c;
}

}  // namespace robodamp::milling
