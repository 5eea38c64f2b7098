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
  std::vector<double> sin_phi, cos_phi;  // at the middle of the bin's step
  std::vector<double> weight;          // share of the bin's step the edge spends in the engagement
  std::vector<char> in_material;       // weight > 0
  std::vector<double> surface_m;       // radial reach of the last pass that cut, per bin (workpiece frame)
  std::vector<char> cut_before;
  std::size_t wall_bin{0};             // bin whose step passes the surface-generating angle
  double wall_fraction{0.0};           // where in that step
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
    st.sin_phi.resize(bins), st.cos_phi.resize(bins), st.weight.resize(bins), st.in_material.resize(bins);
    // Bin i is the step over which the edge goes from i dphi - lag to (i + 1) dphi - lag.
    for (std::size_t i = 0; i < bins; ++i) {
      double a = std::fmod(static_cast<double>(i) * dphi - g.lag_rad, 2.0 * M_PI);
      if (a < 0.0) a += 2.0 * M_PI;
      const double mid = a + 0.5 * dphi;
      st.sin_phi[i] = std::sin(mid), st.cos_phi[i] = std::cos(mid);
      double inside = 0.0;
      for (double turn : {0.0, 2.0 * M_PI})
        inside += std::max(0.0, std::min(a + dphi, e.exit_rad + turn) - std::max(a, e.start_rad + turn));
      st.weight[i] = st.engaged_anywhere ? inside / dphi : 0.0;
      st.in_material[i] = st.weight[i] > 1e-12;
    }
    st.surface_m.assign(bins, 0.0);
    st.cut_before.assign(bins, 0);
    // The step in which the edge passes the surface-generating angle (pi down, 0 up milling), and where.
    const double wall_angle = surface_angle_rad(s.cut.mode);
    double pos = std::fmod(wall_angle + g.lag_rad, 2.0 * M_PI) / dphi;
    if (s.cut.mode == config::MillingMode::kDown) pos -= 1e-9;  // the step that ends at pi, not the next
    const double whole = std::floor(pos);
    st.wall_bin = static_cast<std::size_t>(whole + static_cast<double>(bins)) % bins;
    st.wall_fraction = std::clamp(pos - whole, 0.0, 1.0);
    out.push_back(std::move(st));
  }
  return out;
}

}  // namespace

CutRecord simulate_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                       const config::MaterialConfig& mat, const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1)
    throw std::invalid_argument("simulate_cut: needs rpm > 0 and steps_per_tooth >= 1");
  ToolDynamics dyn(terms, 60.0 / (s.rpm * cutter.teeth) / s.steps_per_tooth);
  return simulate_cut(dyn, cutter, mat, s);
}

CutRecord simulate_cut(CutDynamics& dyn, const Cutter& cutter, const config::MaterialConfig& mat, const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1 || s.revolutions <= s.settle_revolutions)
    throw std::invalid_argument("simulate_cut: needs rpm > 0, steps_per_tooth >= 1, revolutions > settle_revolutions");
  const int n = cutter.teeth, m = s.steps_per_tooth;
  const std::size_t bins = static_cast<std::size_t>(n) * static_cast<std::size_t>(m);
  const double tooth_period_s = 60.0 / (s.rpm * n), h = tooth_period_s / m;
  if (std::abs(dyn.step_s() - h) > 1e-9 * h)
    throw std::invalid_argument("simulate_cut: the dynamics' step is not the tooth period / steps_per_tooth");
  std::vector<SliceState> sl = make_slices(cutter, s, bins);
  std::vector<double> runout_m(static_cast<std::size_t>(n), 0.0);
  for (std::size_t j = 0; j < runout_m.size() && j < s.runout_um.size(); ++j) runout_m[j] = s.runout_um[j] * 1e-6;
  const double ft = s.cut.feed_per_tooth_mm * 1e-3;
  // Each tooth's angular position on the step grid and the feed since the tooth one pitch ahead passed the
  // same angle (uneven pitch: the pitch's share of a revolution times the feed per revolution).
  std::vector<std::size_t> tooth_bin(static_cast<std::size_t>(n));
  std::vector<double> pitch_feed_m(static_cast<std::size_t>(n), ft);
  {
    const bool uneven = static_cast<int>(s.pitch_deg.size()) == n;
    double angle_deg = 0.0;
    for (int j = 0; j < n; ++j) {
      tooth_bin[static_cast<std::size_t>(j)] =
          uneven ? static_cast<std::size_t>(std::lround(angle_deg / 360.0 * static_cast<double>(bins))) % bins
                 : static_cast<std::size_t>(j) * static_cast<std::size_t>(m);
      if (uneven) {
        pitch_feed_m[static_cast<std::size_t>(j)] = ft * n * s.pitch_deg[static_cast<std::size_t>(j)] / 360.0;
        angle_deg += s.pitch_deg[static_cast<std::size_t>(j)];
      }
    }
  }
  const double kt = mat.kt_n_per_mm2 * 1e6, kr = mat.kr_n_per_mm2 * 1e6, kte = mat.kte_n_per_mm * 1e3,
               kre = mat.kre_n_per_mm * 1e3;
  const double exponent = mat.chip_exponent, reference_chip_m = mat.reference_chip_mm * 1e-3;

  CutRecord r;
  r.rpm = s.rpm, r.step_s = h, r.teeth = n, r.steps_per_tooth = m;
  const std::size_t steps = bins * static_cast<std::size_t>(s.revolutions);
  r.settle_steps = bins * static_cast<std::size_t>(s.settle_revolutions);
  r.x_m.reserve(steps), r.y_m.reserve(steps), r.fx_n.reserve(steps), r.fy_n.reserve(steps);
  // The mean cutting force over step k, from the tool's displacement at the middle of the step (q_mid) and
  // the edges' angles there, each edge weighted by the share of the step it spends in the engagement.
  // commit=false would only read; the surface is renewed and the wall recorded at each step.
  struct WallPass {
    SliceState* slice;
    double runout_m;
  };
  std::vector<WallPass> walls;  // this step's
  walls.reserve(sl.size() * static_cast<std::size_t>(n));
  auto cutting_force = [&](std::size_t k, const Eigen::Vector2d& q_mid) {
    const double feed_m = ft * (static_cast<double>(k) + 0.5) / m;  // nominal tool advance along x
    const bool stats = k >= r.settle_steps;
    Eigen::Vector2d f = Eigen::Vector2d::Zero();
    for (SliceState& st : sl) {
      const double db = st.geometry.height_mm * 1e-3, radius = st.geometry.radius_mm * 1e-3;
      for (int j = 0; j < n; ++j) {
        const std::size_t bin = (k + tooth_bin[static_cast<std::size_t>(j)]) % bins;
        if (!st.in_material[bin]) continue;
        const double sp = st.sin_phi[bin], cp = st.cos_phi[bin];
        const double runout = runout_m[static_cast<std::size_t>(j)];
        const double deflection = q_mid(0) * sp + q_mid(1) * cp;
        // Radial reach of this tooth's edge along its direction, in the workpiece's frame.
        const double reach = radius + runout + deflection + feed_m * sp;
        // Before any pass cut here, the workpiece is as the tooth one pitch ahead (which passed this angle
        // a tooth period ago) would have left it with the tool displaced as it is now: the nominal chip,
        // with the two teeth's runout. (A rigid previous pass would leave material near the wall that a
        // tool deflected away from it never reaches, and that steady cut would never remove.)
        const std::size_t prev_tooth = static_cast<std::size_t>((j + 1) % n);
        const double previous = st.cut_before[bin] ? st.surface_m[bin]
                                                   : radius + runout_m[prev_tooth] + deflection +
                                                         (feed_m - pitch_feed_m[static_cast<std::size_t>(j)]) * sp;
        const double chip_xy = reach - previous;
        // The edge passes the surface angle in this step: it makes the wall there (recorded once the step's
        // end is known), whether or not it still removes a chip at that very angle.
        if (stats && bin == st.wall_bin) walls.push_back({&st, runout});
        // Counted over whole steps inside the engagement (a steady cut has a chip everywhere there).
        const bool counted = stats && st.weight[bin] == 1.0;
        if (counted) ++r.engaged_samples;
        if (chip_xy <= 0.0) {
          if (counted) ++r.out_of_cut_samples;  // no chip: no force, the surface stays as it was
          continue;
        }
        const double chip = chip_xy * st.sk, w = st.weight[bin];
        // Linear, or exponential: the coefficients at the reference chip scaled by (h / h_ref)^-exponent.
        const double scale = exponent > 0.0 ? std::pow(chip / reference_chip_m, -exponent) : 1.0;
        const double f_t = kt * scale * db * chip + kte * db, f_r = st.sk * (kr * scale * db * chip + kre * db);
        f(0) += w * (-f_t * cp - f_r * sp);
        f(1) += w * (f_t * sp - f_r * cp);
        st.surface_m[bin] = reach;
        st.cut_before[bin] = 1;
      }
    }
    return f;
  };
  // Each step: the displacement at its middle from the start and a look-ahead to its end with the last
  // force held, the mean force over the step from there, and the exact response to that force held
  // (second order in h; the force at the step's start alone would act half a step late).
  Eigen::Vector2d f_last = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < steps; ++k) {
    if (k == r.settle_steps) dyn.settled();
    const Eigen::Vector2d q = dyn.displacement(), q_end = dyn.predict(f_last);
    walls.clear();
    const Eigen::Vector2d f = cutting_force(k, 0.5 * (q + q_end));
    if (k >= r.settle_steps) {
      r.peak_force_n = std::max(r.peak_force_n, f.norm());
      if ((k + 1) % bins == 0) {  // a revolution ends: the deepest pass of it made the wall
        double sum = 0.0;
        int count = 0;
        for (SliceState& st : sl)
          if (std::isfinite(st.wall_rev_max_m)) {
            st.wall_sum_m += st.wall_rev_max_m, ++st.wall_count;
            sum += st.wall_rev_max_m, ++count;
            st.wall_rev_max_m = -std::numeric_limits<double>::infinity();
          }
        if (count) r.wall_per_rev_um.push_back(-sum / count * 1e6);
      }
    }
    r.x_m.push_back(q(0)), r.y_m.push_back(q(1)), r.fx_n.push_back(f(0)), r.fy_n.push_back(f(1));
    dyn.step(f);
    f_last = f;
    const Eigen::Vector2d q_next = dyn.displacement();
    const double wall = surface_angle_rad(s.cut.mode);
    for (const WallPass& w : walls) {  // the deflection when the edge is at the wall, linear in time
      const Eigen::Vector2d at = q + w.slice->wall_fraction * (q_next - q);
      w.slice->wall_rev_max_m = std::max(w.slice->wall_rev_max_m, w.runout_m + at(0) * std::sin(wall) + at(1) * std::cos(wall));
    }
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
