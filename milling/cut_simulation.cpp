#include "milling/cut_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robodamp::milling {

int steps_per_tooth(const config::TimeDomainConfig& td, double highest_mode_hz, double rpm, int teeth) {
  if (td.steps_per_tooth > 0) return td.steps_per_tooth;
  const double tooth_period_s = 60.0 / (rpm * teeth);
  return std::max(40, static_cast<int>(std::ceil(td.min_steps_per_mode_period * highest_mode_hz * tooth_period_s)));
}

namespace {

// One axial slice: its geometry on its own angular grid (bin i is the angle i dphi - lag, where the
// slice's edge of some tooth sits at every step), and the surface its passes left.
struct SliceState {
  Slice geometry;
  bool engaged_anywhere{false};
  double sk{1.0};                      // sin(kappa)
  std::vector<double> sin_phi, cos_phi;
  std::vector<char> in_material;       // inside the slice's engagement (the workpiece is there)
  std::vector<double> surface_m;       // radial reach of the last pass that cut, per bin (workpiece frame)
  std::vector<char> cut_before;
  std::size_t wall_bin{0};             // bin at the surface-generating angle
  double wall_sum_m{0.0};
  int wall_count{0};
  double wall_rev_max_m{-std::numeric_limits<double>::infinity()};
};

std::vector<SliceState> make_slices(const Cutter& cutter, const CutSettings& s, std::size_t bins) {
  const double dphi = 2.0 * M_PI / static_cast<double>(bins);
  std::vector<SliceState> out;
  for (const Slice& g : slices(cutter, s.cut.axial_mm, s.axial_slices)) {
    SliceState st;
    st.geometry = g;
    st.sk = std::sin(g.kappa_rad);
    const double local_radial = s.cut.radial_mm - (cutter.radius_mm - g.radius_mm);
    st.engaged_anywhere = local_radial > 0.0;
    const Engagement e = engagement(g.radius_mm, std::max(local_radial, 0.0), s.cut.mode);
    st.sin_phi.resize(bins), st.cos_phi.resize(bins), st.in_material.resize(bins);
    for (std::size_t i = 0; i < bins; ++i) {
      double phi = std::fmod(static_cast<double>(i) * dphi - g.lag_rad, 2.0 * M_PI);
      if (phi < 0.0) phi += 2.0 * M_PI;
      st.sin_phi[i] = std::sin(phi), st.cos_phi[i] = std::cos(phi);
      st.in_material[i] = st.engaged_anywhere && phi >= e.start_rad - 1e-12 && phi <= e.exit_rad + 1e-12;
    }
    st.surface_m.assign(bins, 0.0);
    st.cut_before.assign(bins, 0);
    // The engaged bin nearest the wall: the last before exit (down milling, pi) or the first after entry
    // (up milling, 0).
    const double wall_angle = surface_angle_rad(s.cut.mode);
    const double pos = (wall_angle + g.lag_rad) / dphi;
    st.wall_bin = static_cast<std::size_t>(s.cut.mode == config::MillingMode::kDown ? std::floor(pos + 1e-9)
                                                                                       : std::ceil(pos - 1e-9)) %
                  bins;
    out.push_back(std::move(st));
  }
  return out;
}

}  // namespace

CutRecord simulate_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                       const config::MaterialConfig& mat, const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1 || s.revolutions <= s.settle_revolutions)
    throw std::invalid_argument("simulate_cut: needs rpm > 0, steps_per_tooth >= 1, revolutions > settle_revolutions");
  const int n = cutter.teeth, m = s.steps_per_tooth;
  const std::size_t bins = static_cast<std::size_t>(n) * static_cast<std::size_t>(m);
  const double tooth_period_s = 60.0 / (s.rpm * n), h = tooth_period_s / m;
  ToolDynamics dyn(terms, h);
  std::vector<SliceState> sl = make_slices(cutter, s, bins);
  std::vector<double> runout_m(static_cast<std::size_t>(n), 0.0);
  for (std::size_t j = 0; j < runout_m.size() && j < s.runout_um.size(); ++j) runout_m[j] = s.runout_um[j] * 1e-6;
  const double ft = s.cut.feed_per_tooth_mm * 1e-3;
  const double kt = mat.kt_n_per_mm2 * 1e6, kr = mat.kr_n_per_mm2 * 1e6, kte = mat.kte_n_per_mm * 1e3,
               kre = mat.kre_n_per_mm * 1e3;

  CutRecord r;
  r.rpm = s.rpm, r.step_s = h, r.teeth = n, r.steps_per_tooth = m;
  const std::size_t steps = bins * static_cast<std::size_t>(s.revolutions);
  r.settle_steps = bins * static_cast<std::size_t>(s.settle_revolutions);
  r.x_m.reserve(steps), r.y_m.reserve(steps), r.fx_n.reserve(steps), r.fy_n.reserve(steps);
  // The cutting force at step k with the tool displaced by q. commit: this is the step itself (renew the
  // surface, count, record the wall); otherwise a look-ahead that only reads the surface memory.
  auto cutting_force = [&](std::size_t k, const Eigen::Vector2d& q, bool commit) {
    const double feed_m = ft * static_cast<double>(k) / m;  // nominal tool advance along x
    const bool stats = commit && k >= r.settle_steps;
    Eigen::Vector2d f = Eigen::Vector2d::Zero();
    for (SliceState& st : sl) {
      const double db = st.geometry.height_mm * 1e-3, radius = st.geometry.radius_mm * 1e-3;
      for (int j = 0; j < n; ++j) {
        const std::size_t bin = (k + static_cast<std::size_t>(j) * static_cast<std::size_t>(m)) % bins;
        if (!st.in_material[bin]) continue;
        const double sp = st.sin_phi[bin], cp = st.cos_phi[bin];
        const double deflection = q(0) * sp + q(1) * cp;
        // Radial reach of this tooth's edge along its direction, in the workpiece's frame.
        const double reach = radius + runout_m[static_cast<std::size_t>(j)] + deflection + feed_m * sp;
        // Before any pass cut here, the workpiece is as a rigid previous tooth left it.
        const std::size_t prev_tooth = static_cast<std::size_t>((j + n - 1) % n);
        const double previous = st.cut_before[bin] ? st.surface_m[bin]
                                                   : radius + runout_m[prev_tooth] + (feed_m - ft) * sp;
        const double chip_xy = reach - previous;
        // The edge passing the surface-generating angle makes the wall there (the deepest pass of a
        // revolution is what remains), whether or not it still removes a chip at that very angle.
        if (stats && bin == st.wall_bin)
          st.wall_rev_max_m = std::max(st.wall_rev_max_m, runout_m[static_cast<std::size_t>(j)] + deflection);
        // Counted away from entry and exit, where the nominal chip itself tends to zero.
        const bool counted = stats && sp > 0.1;
        if (counted) ++r.engaged_samples;
        if (chip_xy <= 0.0) {
          if (counted) ++r.out_of_cut_samples;  // no chip: no force, the surface stays as it was
          continue;
        }
        const double chip = chip_xy * st.sk;
        const double f_t = kt * db * chip + kte * db, f_r = st.sk * (kr * db * chip + kre * db);
        f(0) += -f_t * cp - f_r * sp;
        f(1) += f_t * sp - f_r * cp;
        if (!commit) continue;
        st.surface_m[bin] = reach;
        st.cut_before[bin] = 1;
      }
    }
    return f;
  };
  // Each step: the force at its start, a look-ahead to its end with that force held, and the exact
  // response to the force going linearly between the two (second order in h; a held force alone would
  // act half a step late).
  Eigen::Vector2d q = dyn.displacement();
  for (std::size_t k = 0; k < steps; ++k) {
    const Eigen::Vector2d f0 = cutting_force(k, q, true);
    const Eigen::Vector2d f1 = cutting_force(k + 1, dyn.predict(f0), false);
    if (k >= r.settle_steps) {
      r.peak_force_n = std::max(r.peak_force_n, f0.norm());
      if ((k + 1) % bins == 0)  // a revolution ends: the deepest pass of it made the wall
        for (SliceState& st : sl)
          if (std::isfinite(st.wall_rev_max_m)) {
            st.wall_sum_m += st.wall_rev_max_m, ++st.wall_count;
            st.wall_rev_max_m = -std::numeric_limits<double>::infinity();
          }
    }
    r.x_m.push_back(q(0)), r.y_m.push_back(q(1)), r.fx_n.push_back(f0(0)), r.fy_n.push_back(f0(1));
    dyn.step(f0, f1);
    q = dyn.displacement();
  }
  // Positive = undercut: the edge reached less far towards the wall than nominal.
  double sum = 0.0;
  int count = 0;
  for (const SliceState& st : sl) {
    const double w = st.wall_count ? -st.wall_sum_m / st.wall_count * 1e6 : std::nan("");
    r.wall_um.push_back(w);
    if (st.wall_count) sum += w, ++count;
  }
  r.sle_um = count ? sum / count : std::nan("");
  return r;
}

}  // namespace robodamp::milling
