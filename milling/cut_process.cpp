#include "milling/cut_process.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "milling/cut_simulation.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

CutProcess::CutProcess(const Cutter& cutter, const config::MaterialConfig& mat, const CutSettings& s) {
  if (!(s.rpm > 0.0) || s.steps_per_tooth < 1)
    throw std::invalid_argument("CutProcess: needs rpm > 0 and steps_per_tooth >= 1");
  const int n = cutter.teeth, m = s.steps_per_tooth;
  teeth_ = n, steps_per_tooth_ = m;
  bins_ = static_cast<std::size_t>(n) * static_cast<std::size_t>(m);
  step_s_ = 60.0 / (s.rpm * n) / m;
  wall_angle_rad_ = surface_angle_rad(s.cut.mode);
  const double dphi = kTwoPi / static_cast<double>(bins_);
  for (const Slice& g : slices(cutter, s.cut.axial_mm, s.axial_slices)) {
    SliceState st;
    st.z_m = g.z_mm * 1e-3, st.height_m = g.height_mm * 1e-3, st.radius_m = g.radius_mm * 1e-3;
    st.lag_rad = g.lag_rad;
    st.sk = std::sin(g.kappa_rad);
    const double local_radial = slice_radial_mm(cutter, g, s.cut.radial_mm);
    const bool engaged_anywhere = local_radial > 0.0;
    const Engagement e = engagement(g.radius_mm, std::max(local_radial, 0.0), s.cut.mode);
    st.sin_phi.resize(bins_), st.cos_phi.resize(bins_), st.weight.resize(bins_), st.in_material.resize(bins_);
    // Bin i is the step over which the edge goes from i dphi - lag to (i + 1) dphi - lag.
    for (std::size_t i = 0; i < bins_; ++i) {
      double a = std::fmod(static_cast<double>(i) * dphi - g.lag_rad, kTwoPi);
      if (a < 0.0) a += kTwoPi;
      const double mid = a + 0.5 * dphi;
      st.sin_phi[i] = std::sin(mid), st.cos_phi[i] = std::cos(mid);
      double inside = 0.0;
      for (double turn : {0.0, kTwoPi})
        inside += std::max(0.0, std::min(a + dphi, e.exit_rad + turn) - std::max(a, e.start_rad + turn));
      st.weight[i] = engaged_anywhere ? inside / dphi : 0.0;
      st.in_material[i] = st.weight[i] > 1e-12;
    }
    st.surface_m.assign(bins_, 0.0);
    st.surface_feed_m.assign(bins_, 0.0);
    st.cut_before.assign(bins_, 0);
    // The step in which the edge passes the surface-generating angle (pi down, 0 up milling), and where.
    double pos = std::fmod(wall_angle_rad_ + g.lag_rad, kTwoPi) / dphi;
    if (s.cut.mode == config::MillingMode::kDown) pos -= 1e-9;  // the step that ends at pi, not the next
    const double whole = std::floor(pos);
    st.wall_bin = static_cast<std::size_t>(whole + static_cast<double>(bins_)) % bins_;
    st.wall_fraction = std::clamp(pos - whole, 0.0, 1.0);
    slices_.push_back(std::move(st));
  }
  runout_m_.assign(static_cast<std::size_t>(n), 0.0);
  for (std::size_t j = 0; j < runout_m_.size() && j < s.runout_um.size(); ++j) runout_m_[j] = s.runout_um[j] * 1e-6;
  feed_per_tooth_m_ = s.cut.feed_per_tooth_mm * 1e-3;
  // Each tooth's angular position on the step grid and the feed since the tooth one pitch ahead passed the
  // same angle (uneven pitch: the pitch's share of a revolution times the feed per revolution).
  tooth_bin_.resize(static_cast<std::size_t>(n));
  pitch_feed_m_.assign(static_cast<std::size_t>(n), feed_per_tooth_m_);
  const bool uneven = static_cast<int>(s.pitch_deg.size()) == n;
  double angle_deg = 0.0;
  for (int j = 0; j < n; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    tooth_bin_[uj] = uneven
                         ? static_cast<std::size_t>(std::lround(angle_deg / 360.0 * static_cast<double>(bins_))) % bins_
                         : uj * static_cast<std::size_t>(m);
    if (uneven) {
      pitch_feed_m_[uj] = feed_per_tooth_m_ * n * s.pitch_deg[uj] / 360.0;
      angle_deg += s.pitch_deg[uj];
    }
  }
  kt_ = mat.kt_n_per_mm2 * 1e6, kr_ = mat.kr_n_per_mm2 * 1e6, kte_ = mat.kte_n_per_mm * 1e3,
  kre_ = mat.kre_n_per_mm * 1e3;
  exponent_ = mat.chip_exponent, reference_chip_m_ = mat.reference_chip_mm * 1e-3;
  walls_.reserve(slices_.size() * static_cast<std::size_t>(n));
  wall_per_rev_um_.reserve(static_cast<std::size_t>(std::max(s.revolutions, 0)) + 1);
}

Eigen::Vector2d CutProcess::force(std::size_t k, const Eigen::Vector2d& q_mid, bool stats) noexcept {
  walls_.clear();
  const int n = teeth_;
  const double feed_m = feed_at_m(static_cast<double>(k) + 0.5);  // nominal advance along x
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (SliceState& st : slices_) {
    const double db = st.height_m, radius = st.radius_m;
    for (int j = 0; j < n; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      const std::size_t bin = (k + tooth_bin_[uj]) % bins_;
      if (!st.in_material[bin]) continue;
      const double sp = st.sin_phi[bin], cp = st.cos_phi[bin];
      const double runout = runout_m_[uj];
      const double deflection = q_mid(0) * sp + q_mid(1) * cp;
      // Radial reach of this tooth's edge along its direction, in the workpiece's frame.
      const double reach = radius + runout + deflection + feed_m * sp;
      // Before any pass cut here, the workpiece is as the tooth one pitch ahead (which passed this angle
      // a tooth period ago) would have left it with the tool displaced as it is now: the nominal chip,
      // with the two teeth's runout. (A rigid previous pass would leave material near the wall that a
      // tool deflected away from it never reaches, and that steady cut would never remove.)
      const auto prev_tooth = static_cast<std::size_t>((j + 1) % n);
      const double previous = st.cut_before[bin]
                                  ? st.surface_m[bin]
                                  : radius + runout_m_[prev_tooth] + deflection + (feed_m - pitch_feed_m_[uj]) * sp;
      const double chip_xy = reach - previous;
      // The edge passes the surface angle in this step: it makes the wall there (recorded once the step's
      // end is known), whether or not it still removes a chip at that very angle.
      if (stats && bin == st.wall_bin) walls_.push_back({&st, runout});
      // Counted over whole steps inside the engagement (a steady cut has a chip everywhere there).
      const bool counted = stats && st.weight[bin] == 1.0;
      if (counted) ++engaged_samples_;
      if (chip_xy <= 0.0) {
        if (counted) ++out_of_cut_samples_;  // no chip: no force, the surface stays as it was
        continue;
      }
      const double chip = chip_xy * st.sk, w = st.weight[bin];
      // Linear, or exponential: the coefficients at the reference chip scaled by (h / h_ref)^-exponent.
      const double scale = exponent_ > 0.0 ? std::pow(chip / reference_chip_m_, -exponent_) : 1.0;
      const double f_t = kt_ * scale * db * chip + kte_ * db, f_r = st.sk * (kr_ * scale * db * chip + kre_ * db);
      f(0) += w * (-f_t * cp - f_r * sp);
      f(1) += w * (f_t * sp - f_r * cp);
      st.surface_m[bin] = reach;
      st.surface_feed_m[bin] = feed_m;
      st.cut_before[bin] = 1;
    }
  }
  if (stats && (k + 1) % bins_ == 0) {  // a revolution ends: the deepest pass of it made the wall
    double sum = 0.0;
    int count = 0;
    for (SliceState& st : slices_)
      if (std::isfinite(st.wall_rev_max_m)) {
        st.wall_sum_m += st.wall_rev_max_m, ++st.wall_count;
        sum += st.wall_rev_max_m, ++count;
        st.wall_rev_max_m = -std::numeric_limits<double>::infinity();
      }
    if (count && wall_per_rev_um_.size() < wall_per_rev_um_.capacity()) wall_per_rev_um_.push_back(-sum / count * 1e6);
  }
  return f;
}

std::size_t CutProcess::continue_from(const CutProcess& before, std::size_t steps) noexcept {
  // Tooth 0 at the spindle angle `before` reached, on this grid.
  const double turn = static_cast<double>(steps % before.bins_) / static_cast<double>(before.bins_);
  const std::size_t k = static_cast<std::size_t>(std::lround(turn * static_cast<double>(bins_))) % bins_;
  feed_origin_m_ = before.feed_at_m(static_cast<double>(steps));
  first_step_ = k;
  const double depth_before_m =
      before.slices_.empty() ? 0.0 : before.slices_.back().z_m + 0.5 * before.slices_.back().height_m;
  const double dphi = kTwoPi / static_cast<double>(bins_), dphi_before = kTwoPi / static_cast<double>(before.bins_);
  for (SliceState& st : slices_) {
    std::fill(st.cut_before.begin(), st.cut_before.end(), 0);
    if (st.z_m >= depth_before_m) continue;  // fresh material: no pass cut here yet
    // The slice of `before` at this height (its slices are of equal height).
    const auto j =
        std::min(before.slices_.size() - 1,
                 static_cast<std::size_t>(st.z_m / depth_before_m * static_cast<double>(before.slices_.size())));
    const SliceState& old = before.slices_[j];
    for (std::size_t i = 0; i < bins_; ++i) {
      // Bin i holds the workpiece angle i dphi - lag; the same angle on the old slice's grid.
      const double at = (static_cast<double>(i) * dphi - st.lag_rad + old.lag_rad) / dphi_before;
      const long n = static_cast<long>(before.bins_);
      const auto b = static_cast<std::size_t>(((std::lround(at) % n) + n) % n);
      // The reach is along the edge's direction; the nearest old bin's direction differs by up to half a
      // bin, which matters for the feed travelled (metres after an hour), not for the tool's deflection
      // (micrometres): the feed's part is projected onto this bin's direction.
      st.surface_feed_m[i] = old.surface_feed_m[b];
      st.surface_m[i] = old.surface_m[b] + old.surface_feed_m[b] * (st.sin_phi[i] - old.sin_phi[b]);
      st.cut_before[i] = old.cut_before[b];
    }
  }
  return k;
}

void CutProcess::end_step(const Eigen::Vector2d& q, const Eigen::Vector2d& q_next) noexcept {
  for (const WallPass& w : walls_) {  // the deflection when the edge is at the wall, linear in time
    const Eigen::Vector2d at = q + w.slice->wall_fraction * (q_next - q);
    w.slice->wall_rev_max_m = std::max(
        w.slice->wall_rev_max_m, w.runout_m + at(0) * std::sin(wall_angle_rad_) + at(1) * std::cos(wall_angle_rad_));
  }
}

std::vector<double> CutProcess::wall_um() const {
  std::vector<double> out;
  for (const SliceState& st : slices_)
    out.push_back(st.wall_count ? -st.wall_sum_m / st.wall_count * 1e6 : std::nan(""));
  return out;
}

double CutProcess::sle_um() const {
  double sum = 0.0;
  int count = 0;
  for (const double w : wall_um())
    if (std::isfinite(w)) sum += w, ++count;
  return count ? sum / count : std::nan("");
}

}  // namespace robodamp::milling
