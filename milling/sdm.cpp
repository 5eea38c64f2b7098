#include "milling/sdm.hpp"
#include "milling/dominant_multiplier.hpp"
#include "milling/interval_collocation.hpp"
#include "milling/interval_exp.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace robodamp::milling {

SdmModel::SdmModel(const std::vector<CutterModalTerm>& terms, const Cutter& cutter, const config::MaterialConfig& mat,
                   config::MillingMode mode, double radial_mm, int axial_slices, int steps_per_period)
    : cutter_(cutter), material_(mat), mode_(mode), radial_mm_(radial_mm), slices_(axial_slices), m_(steps_per_period) {
  if (m_ < 2) throw std::invalid_argument("SdmModel: needs at least 2 steps per period");
  const ToolDynamics dyn(terms, 1.0);  // only its continuous model is used
  a_ = dyn.a(), b_ = dyn.b(), c_ = dyn.c();
  // Each mode's state (q, q') as (wn q, q'): the same monodromy up to a similarity (the same multipliers and
  // displacements), but a block [[0, wn], [-wn, -2 zeta wn]] of norm ~wn instead of wn^2. The matrix
  // exponential's scaling and squaring then needs ~log2(wn) fewer squarings per interval (17 fewer at
  // 1156 rpm on the 46-mode industrial robot, whose highest mode is 6.6 kHz).
  for (Eigen::Index k = 0; k + 1 < a_.rows(); k += 2) {
    const double wn2 = -a_(k + 1, k);
    if (!(wn2 > 0.0) || a_(k, k + 1) != 1.0 || a_(k, k) != 0.0) continue;  // not a mode's block: left as it is
    const double wn = std::sqrt(wn2);
    a_(k, k + 1) = wn, a_(k + 1, k) = -wn;
    b_.row(k) *= wn;
    c_.col(k) /= wn;
  }
  // ToolDynamics builds one 2 x 2 block per mode; the interval's exponential relies on it.
  for (Eigen::Index k = 0; k < a_.rows(); k += 2) blocks_.emplace_back(a_.block(k, k, 2, 2));
  Eigen::MatrixXd check = Eigen::MatrixXd::Zero(a_.rows(), a_.cols());
  for (Eigen::Index k = 0; k < a_.rows(); k += 2) check.block(k, k, 2, 2) = a_.block(k, k, 2, 2);
  if (a_.rows() % 2 != 0 || check != a_)
    throw std::logic_error("SdmModel: the structure's model is not block diagonal");
}

DirectionalMatrix::DirectionalMatrix(const Cutter& cutter, const config::MaterialConfig& material,
                                     config::MillingMode mode, double radial_mm, int axial_slices, double axial_mm)
    : teeth_(cutter.teeth), kt_(material.kt_n_per_mm2 * 1e6), kr_(material.kr_n_per_mm2 * 1e6) {
  for (const Slice& s : slices(cutter, axial_mm, axial_slices)) {
    const double local_radial = slice_radial_mm(cutter, s, radial_mm);
    if (local_radial <= 0.0) continue;
    EngagedSlice es{s, engagement(s.radius_mm, local_radial, mode), std::sin(s.kappa_rad), {}};
    for (int j = 0; j < teeth_; ++j) {
      const double offset = kTwoPi * j / teeth_ - s.lag_rad;
      es.teeth.push_back({offset, std::sin(offset), std::cos(offset)});
    }
    slices_.push_back(std::move(es));
  }
}

Eigen::Matrix2d DirectionalMatrix::mean(double phi0, double dphi, int sub) const {
  Eigen::Matrix2d mean = Eigen::Matrix2d::Zero();
  for (int i = 0; i < sub; ++i) {
    const double spindle = phi0 + (i + 0.5) / sub * dphi;
    const double ss = std::sin(spindle), cs = std::cos(spindle);
    for (const EngagedSlice& es : slices_) {
      const Engagement& e = es.engagement;
      const double sk = es.sin_kappa, w = es.slice.height_mm * 1e-3 * sk / sub;
      for (const ToothOffset& t : es.teeth) {
        // The spindle's angle is within one tooth period and the offset within a turn less the lag, so the
        // sum is almost always in [0, 2 pi) already, where fmod would return it as it is.
        double phi = spindle + t.rad;
        if (!(phi >= 0.0 && phi < kTwoPi)) phi = std::fmod(phi, kTwoPi);
        if (phi < 0.0) phi += kTwoPi;
        if (phi < e.start_rad || phi > e.exit_rad) continue;
        // sin and cos of spindle + offset by the angle sum: one sine and cosine per sub-sample, not per tooth
        // and slice.
        const double sp = ss * t.cos + cs * t.sin, cp = cs * t.cos - ss * t.sin;
        const double fx = -kt_ * cp - kr_ * sk * sp, fy = kt_ * sp - kr_ * sk * cp;
        mean(0, 0) += w * fx * sp, mean(0, 1) += w * fx * cp;
        mean(1, 0) += w * fy * sp, mean(1, 1) += w * fy * cp;
      }
    }
  }
  return mean;
}

std::complex<double> SdmModel::multiplier(double axial_mm, double rpm) const {
  return multiplier(axial_mm, rpm, nullptr);
}

double floquet_chatter_hz(std::complex<double> mu, const std::vector<double>& t, const Eigen::VectorXcd& history,
                          double tooth_hz) {
  const auto k = static_cast<int>(t.size());
  const std::complex<double> log_mu = std::log(mu), i(0.0, 1.0);
  double best_energy = -1.0, best_hz = 0.0;
  for (int m = -k / 2; m <= k / 2; ++m) {
    std::complex<double> cx = 0.0, cy = 0.0;
    for (int q = 0; q < k; ++q) {
      const std::complex<double> w = std::exp(-t[static_cast<std::size_t>(q)] * log_mu -
                                              kTwoPi * i * static_cast<double>(m) * t[static_cast<std::size_t>(q)]);
      cx += w * history(2 * q), cy += w * history(2 * q + 1);
    }
    const double energy = std::norm(cx) + std::norm(cy);
    if (energy > best_energy) best_energy = energy, best_hz = std::abs((log_mu.imag() / (kTwoPi) + m) * tooth_hz);
  }
  return best_hz;
}

std::complex<double> SdmModel::multiplier(double axial_mm, double rpm, double* chatter_hz) const {
  const Eigen::MatrixXd z = monodromy(axial_mm, rpm);
  if (chatter_hz == nullptr) return DominantMultiplier{}(z);
  return dominant(z, rpm, chatter_hz);
}

// long: one monodromy matrix over a tooth period (the hot loop of the open loop's accurate method)
Eigen::MatrixXd SdmModel::monodromy(double axial_mm, double rpm, Collocations* kept) const {
  const Eigen::Index n = a_.rows(), d = n + 2 * m_;
  const double h = 60.0 / (rpm * cutter_.teeth) / m_;
  // Rows: the modes' states, then the delayed displacements q_{i-1} .. q_{i-m} in a ring of m slots of two rows
  // (slot (first + j) mod m holds q_{i-1-j}): each interval writes its new sample over the oldest instead of
  // moving the whole history down (the copy was half the work of a few-mode structure). The ring is put back
  // in order at the end; the arithmetic is the same.
  Eigen::MatrixXd z = Eigen::MatrixXd::Identity(d, d), x_next(n, d), e;
  auto slot = [&](int j) { return n + 2 * static_cast<Eigen::Index>(j % m_); };
  int first = 0;
  // The history enters from its oldest samples: before interval i only the oldest i + 2 slots have been read,
  // so the states' columns of the others are still zero and the products skip them (live: the first column
  // that may not be).
  Eigen::Index live = d;
  IntervalExp interval(blocks_, c_);
  const std::vector<Eigen::Matrix2d> free = interval.free_blocks(h);
  const std::vector<Eigen::Matrix2d> cut = directional_means(axial_mm);
  Collocations own;
  Collocations& made = kept != nullptr ? *kept : own;
  IntervalCollocation* collocation = nullptr;
  if (const int p = collocation_nodes(cut, h); p > 0) {
    if (made.h != h) made.by_nodes.clear(), made.h = h;
    collocation = &made.by_nodes.try_emplace(p, blocks_, b_, c_, h, p, free).first->second;
  }
  for (int i = 0; i < m_; ++i) {
    const Eigen::Matrix2d& mi = cut[static_cast<std::size_t>(i)];
    // x' = (A + B M C) x - B M q(t - tau); the delayed q goes linearly from q_{i-m} to q_{i-m+1}.
    const auto old_x = z.topRows(n);
    const Eigen::Index oldest = slot(first + m_ - 1), next_oldest = slot(first + m_ - 2);  // q_{i-m}, q_{i-m+1}
    const Eigen::Index tail = d - live;
    if (mi.isZero(0.0)) {  // no tooth cuts: each mode on its own
      for (std::size_t k = 0; k < free.size(); ++k) {
        const auto r = static_cast<Eigen::Index>(2 * k);
        x_next.block(r, 0, 2, n).noalias() = free[k] * z.block(r, 0, 2, n);
        if (tail) x_next.block(r, live, 2, tail).noalias() = free[k] * z.block(r, live, 2, tail);
      }
    } else {
      // The delayed samples reach their own columns, at 2 (m - 1 - i) and 2 (m - 2 - i) past n, first here.
      live = std::min(live, n + 2 * static_cast<Eigen::Index>(std::max(0, m_ - 2 - i)));
      const Eigen::Index now = d - live;
      if (collocation) {
        collocation->set_cut(mi);
        collocation->step(old_x.leftCols(n), z.block(oldest, 0, 2, n), z.block(next_oldest, 0, 2, n),
                          x_next.leftCols(n));
        collocation->step(old_x.rightCols(now), z.block(oldest, live, 2, now), z.block(next_oldest, live, 2, now),
                          x_next.rightCols(now));
      } else {
        interval.compute(b_ * mi, h, e);
        const Eigen::MatrixXd ramp = e.block(0, n + 2, n, 2) / h, held_less_ramp = e.block(0, n, n, 2) - ramp;
        x_next.leftCols(n).noalias() = e.topLeftCorner(n, n) * old_x.leftCols(n);
        x_next.rightCols(now).noalias() = e.topLeftCorner(n, n) * old_x.rightCols(now);
        x_next.leftCols(n).noalias() += held_less_ramp * z.block(oldest, 0, 2, n);
        x_next.rightCols(now).noalias() += held_less_ramp * z.block(oldest, live, 2, now);
        x_next.leftCols(n).noalias() += ramp * z.block(next_oldest, 0, 2, n);
        x_next.rightCols(now).noalias() += ramp * z.block(next_oldest, live, 2, now);
      }
    }
    z.middleRows(oldest, 2).noalias() = c_ * old_x;  // q_i over q_{i-m}, which is no longer needed
    first = (first + m_ - 1) % m_;                   // q_i is the newest now
    z.block(0, 0, n, n) = x_next.leftCols(n);
    z.block(0, live, n, d - live) = x_next.rightCols(d - live);
  }
  Eigen::MatrixXd ordered(d, d);
  ordered.topRows(n) = z.topRows(n);
  for (int j = 0; j < m_; ++j) ordered.middleRows(n + 2 * j, 2) = z.middleRows(slot(first + j), 2);
  return ordered;
}

std::vector<Eigen::Matrix2d> SdmModel::directional_means(double axial_mm) const {
  const DirectionalMatrix directional(cutter_, material_, mode_, radial_mm_, slices_, axial_mm);
  const double dphi = kTwoPi / (cutter_.teeth * m_);  // spindle angle per interval
  constexpr int kSub = 8;
  std::vector<Eigen::Matrix2d> out;
  out.reserve(static_cast<std::size_t>(m_));
  for (int i = 0; i < m_; ++i) out.push_back(directional.mean(i * dphi, dphi, kSub));
  return out;
}

int SdmModel::collocation_nodes(const std::vector<Eigen::Matrix2d>& cut, double h) const {
  // Only for a structure of 8 modes or more (every few-mode job, so every preset, keeps the dense exponential to
  // the bit), and where the correction's rank 2p is at most the modes' state (below).
  if (!low_rank_ || 4 * IntervalCollocation::kMinNodes > a_.rows()) return 0;
  // rho bounds |A + B M C|: the largest block's norm plus the cut's rank-2 term's (the largest singular value
  // of B M C, from the 2 x 2 (B M)^T (B M) C C^T).
  double rho_a = 0.0, rho_cut = 0.0;
  for (const Eigen::Matrix2d& a : blocks_) rho_a = std::max(rho_a, a.operatorNorm());
  const Eigen::Matrix2d cct = c_ * c_.transpose();
  for (const Eigen::Matrix2d& mi : cut) {
    if (mi.isZero(0.0)) continue;
    const Eigen::MatrixXd bm = b_ * mi;
    const Eigen::Matrix2d g = (bm.transpose() * bm) * cct;
    const double half = 0.5 * g.trace(), disc = std::max(0.0, half * half - g.determinant());
    rho_cut = std::max(rho_cut, std::sqrt(std::max(0.0, half + std::sqrt(disc))));
  }
  const int p = IntervalCollocation::nodes_for((rho_a + rho_cut) * h);
  // Worth it where the correction's rank 2p is at most the modes' state: on the 46-mode robot (n = 92) one
  // monodromy matrix by collocation against the dense exponential took 15.1 against 22.8 ms at 1156 rpm
  // (p = 33), 12.1 against 21.0 ms at 2500 rpm, and 35.1 against 25.2 ms at 500 rpm (p = 53 > n / 2: dense).
  return 2 * p > a_.rows() ? 0 : p;
}

std::complex<double> SdmModel::dominant(const Eigen::MatrixXd& z, double rpm, double* chatter_hz) const {
  const std::complex<double> mu = dense_dominant_multiplier(z);
  if (chatter_hz) *chatter_hz = chatter_hz_of(z, mu, rpm);
  return mu;
}

double SdmModel::chatter_hz_of(const Eigen::MatrixXd& z, std::complex<double> mu, double rpm) const {
  // History slot j holds q at -(j + 1) / m tooth periods.
  std::vector<double> t(static_cast<std::size_t>(m_));
  for (int j = 0; j < m_; ++j) t[static_cast<std::size_t>(j)] = -(j + 1.0) / m_;
  return floquet_chatter_hz(mu, t, eigenvector_for(z, mu).segment(a_.rows(), 2 * m_), rpm * cutter_.teeth / 60.0);
}

DepthBracket find_critical_depth(const std::function<double(double)>& ln_mu, double guess_mm, double rel_tol,
                                 double first_step) {
  constexpr double kMaxMm = 1e3, kMinMm = 1e-6;
  // Each step from the guess the square of the last, up to kBracketStep (every step kBracketStep by default):
  // a guess within a few per cent is bracketed that closely, a poor one in a few more steps.
  double step = std::clamp(first_step, 1.0 + 1e-3, kBracketStep);
  const auto grow = [&] { step = std::min(kBracketStep, step * step); };
  double lo = 0.0, hi = 0.0, g_lo = 0.0, g_hi = 0.0;
  double b = std::isfinite(guess_mm) && guess_mm > 0.0 ? guess_mm : 1.0;
  if (const double g0 = ln_mu(b); g0 < 0.0) {
    lo = b, g_lo = g0;
    for (;;) {
      b *= step;
      grow();
      if (b > kMaxMm) return {lo, std::numeric_limits<double>::infinity()};
      const double gb = ln_mu(b);
      if (gb >= 0.0) {
        hi = b, g_hi = gb;
        break;
      }
      lo = b, g_lo = gb;
    }
  } else {
    hi = b, g_hi = g0;
    for (;;) {
      b /= step;
      grow();
      if (b < kMinMm) throw std::runtime_error("semi-discretization: the cut is unstable at any depth");
      const double gb = ln_mu(b);
      if (gb < 0.0) {
        lo = b, g_lo = gb;
        break;
      }
      hi = b, g_hi = gb;
    }
  }
  int side = 0;
  while (hi - lo > rel_tol * hi) {
    double mid = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
    if (!(mid > lo && mid < hi) || hi - lo > 0.5 * hi) mid = 0.5 * (lo + hi);
    const double gm = ln_mu(mid);
    if (gm < 0.0) {
      lo = mid, g_lo = gm;
      if (side == -1) g_hi *= 0.5;
      side = -1;
    } else {
      hi = mid, g_hi = gm;
      if (side == 1) g_lo *= 0.5;
      side = 1;
    }
  }
  return {lo, hi};
}

SdmPoint SdmModel::critical(double rpm, double guess_mm, double rel_tol, double first_step) const {
  if (!(guess_mm > 0.0)) throw std::invalid_argument("SdmModel::critical: the first guess must be > 0 mm");
  Eigen::MatrixXd z_hi;  // the monodromy matrix and its multiplier at the last unstable depth: the bracket's hi
  std::complex<double> mu_hi;
  DominantMultiplier largest;
  Collocations kept;
  const DepthBracket br = find_critical_depth(
      [&](double b) {
        Eigen::MatrixXd z = monodromy(b, rpm, &kept);
        const std::complex<double> mu = largest(z);
        const double ln_mu = std::log(std::abs(mu));
        if (ln_mu >= 0.0) z_hi.swap(z), mu_hi = mu;
        return ln_mu;
      },
      guess_mm, rel_tol, first_step);
  SdmPoint p;
  p.rpm = rpm;
  p.critical_depth_mm = br.lo_mm;
  if (!std::isfinite(br.hi_mm)) {
    p.critical_depth_mm = br.hi_mm;
    return p;
  }
  p.chatter_hz = chatter_hz_of(z_hi, mu_hi, rpm);
  // Period doubling when the critical multiplier is (nearly) real and negative.
  p.type = mu_hi.real() < 0.0 && std::abs(mu_hi.imag()) < 1e-3 * std::abs(mu_hi) ? CutClass::kFlip : CutClass::kHopf;
  return p;
}

}  // namespace robodamp::milling
