#include "milling/sampled_sdm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "milling/tool_dynamics.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

namespace {

using Eigen::MatrixXd;

// Cutter frame -> machine frame (Structure::frf_cutter): a feed along +y makes the cutter's x the
// machine's y and its y the machine's -x. f_machine = R f_cutter, q_cutter = R^T q_machine.
Eigen::Matrix2d to_machine(config::Axis feed) {
  return feed == config::Axis::kX ? Eigen::Matrix2d::Identity() : (Eigen::Matrix2d() << 0.0, -1.0, 1.0, 0.0).finished();
}

void append_block(MatrixXd& a, MatrixXd& b, MatrixXd& c, const MatrixXd& ai, const MatrixXd& bi, const MatrixXd& ci) {
  const Eigen::Index n = a.rows(), m = ai.rows();
  MatrixXd a2 = MatrixXd::Zero(n + m, n + m), b2(n + m, 2), c2(2, n + m);
  a2.topLeftCorner(n, n) = a;
  a2.bottomRightCorner(m, m) = ai;
  b2 << b, bi;
  c2 << c, ci;
  a.swap(a2), b.swap(b2), c.swap(c2);
}

// Lagrange weights of the quadratic through (t0, t1, t2) at t.
Eigen::Vector3d lagrange(double t0, double t1, double t2, double t) {
  return {(t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2)), (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2)),
          (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1))};
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

}  // namespace

SampledSdm::SampledSdm(const Structure& damped, const Cutter& cutter, const config::MaterialConfig& material,
                       config::MillingMode mode, double radial_mm, config::Axis feed_axis, SampledSdmSettings settings)
    : parts_(damped.controller_parts()),
      cutter_(cutter),
      material_(material),
      mode_(mode),
      radial_mm_(radial_mm),
      feed_axis_(feed_axis),
      settings_(settings) {
  if (parts_.empty()) throw std::invalid_argument("SampledSdm: the structure has no controller part");
  if (settings_.min_grid_per_period < 3)
    throw std::invalid_argument("SampledSdm: needs at least 3 grid points per period");
  for (const auto& p : parts_) {
    const double t = 1.0 / p.model->loop_rate_hz();
    if (tick_s_ > 0.0 && std::abs(t - tick_s_) > 1e-12 * t)
      throw std::invalid_argument("SampledSdm: controller parts with different loop rates");
    tick_s_ = t;
    per_speed_ = per_speed_ || p.model->config().controller.harmonic_notch.has_value();
  }
  // The modal tables only: the controller parts' robot is in their loops (as the damped time-domain cut).
  const Structure tables(damped.modal_terms_by_pair(), damped.name());
  tables_ = cutter_modal_terms(tables, feed_axis);
  base_ = system_at(0.0);
}

std::optional<std::string> sampled_speed_problem(double rpm, int teeth, double loop_rate_hz) {
  const double tick_s = 1.0 / loop_rate_hz;
  const double ticks = std::round(60.0 / (rpm * teeth) / tick_s);
  if (rpm > 0.0 && std::isfinite(rpm) && ticks >= SampledSdmSettings::kMinTicksPerTooth) return std::nullopt;
  const double max_rpm = 60.0 / (teeth * (SampledSdmSettings::kMinTicksPerTooth - 0.5) * tick_s) * (1.0 - 1e-9);
  return "spindle speed = " + fmt(rpm) +
         " rpm: the sampled loop's semi-discretization needs a tooth period of at least " +
         std::to_string(SampledSdmSettings::kMinTicksPerTooth) + " loop periods (" +
         fmt(SampledSdmSettings::kMinTicksPerTooth * tick_s * 1e3) + " ms at " + fmt(loop_rate_hz) +
         " Hz), allowed range (0, " + fmt(max_rpm) + "] rpm";
}

int SampledSdm::ticks_per_tooth(double rpm) const {
  if (auto p = sampled_speed_problem(rpm, cutter_.teeth, loop_rate_hz())) throw std::invalid_argument(*p);
  return static_cast<int>(std::round(60.0 / (rpm * cutter_.teeth) / tick_s_));
}

double SampledSdm::stepped_rpm(double rpm) const { return 60.0 / (cutter_.teeth * ticks_per_tooth(rpm) * tick_s_); }

double SampledSdm::max_rpm() const {
  return 60.0 / (cutter_.teeth * (SampledSdmSettings::kMinTicksPerTooth - 0.5) * tick_s_) * (1.0 - 1e-9);
}

SampledSdm::System SampledSdm::system_at(double rpm) const {
  System s;
  s.a.resize(0, 0), s.b.resize(0, 2), s.c.resize(2, 0);
  const Eigen::Matrix2d r = to_machine(feed_axis_);
  for (const auto& part : parts_) {
    std::shared_ptr<const analysis::LoopModel> model = part.model;
    if (per_speed_ && rpm > 0.0) model = std::make_shared<const analysis::LoopModel>(part.model->at_speed(rpm));
    const auto d = static_cast<Eigen::Index>(part.direction);
    if (!part.across) {
      const analysis::SampledPath p = model->sampled_path(part.location, part.gain_ns_per_m, part.polarity);
      append_block(s.a, s.b, s.c, p.a, p.b * r.row(d), r.transpose().col(d) * p.c);
      continue;
    }
    // Across the plane: forces along both machine axes in, displacements along both out (machine frame).
    const analysis::SampledPaths p =
        model->sampled_paths({part.location, *part.across}, part.gain_ns_per_m, part.polarity);
    MatrixXd bm(p.b.rows(), 2), cm(2, p.c.cols());
    bm.col(d) = p.b.col(0), bm.col(1 - d) = p.b.col(1);
    cm.row(d) = p.c.row(0), cm.row(1 - d) = p.c.row(1);
    append_block(s.a, s.b, s.c, p.a, bm * r, r.transpose() * cm);
  }
  if (!tables_.empty()) {
    const ToolDynamics dyn(tables_, tick_s_);
    const Eigen::Index n = dyn.a().rows();
    MatrixXd big = MatrixXd::Zero(n + 2, n + 2);
    big.topLeftCorner(n, n) = dyn.a();
    big.topRightCorner(n, 2) = dyn.b();
    const MatrixXd e = (big * tick_s_).exp();
    append_block(s.a, s.b, s.c, e.topLeftCorner(n, n), e.topRightCorner(n, 2), dyn.c());
  }
  // The loop's modes: poles with a frequency below Nyquist and damping below 30 %.
  const Eigen::VectorXcd poles = Eigen::EigenSolver<MatrixXd>(s.a, false).eigenvalues();
  if (poles.cwiseAbs().maxCoeff() >= 1.0)
    throw std::invalid_argument("SampledSdm: the damped loop is unstable without cutting (spectral radius " +
                                fmt(poles.cwiseAbs().maxCoeff()) + ")");
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    if (poles(i).imag() <= 0.0 || std::abs(poles(i)) < 1e-3) continue;
    const std::complex<double> sp = std::log(poles(i)) / tick_s_;
    const double f = std::abs(sp) / (kTwoPi), zeta = -sp.real() / std::abs(sp);
    if (zeta >= 0.3) continue;
    s.highest_mode_hz = std::max(s.highest_mode_hz, f);
  }
  return s;
}

// long: one monodromy matrix over a tooth period on preallocated blocks (the hot loop of the accurate method)
SampledSdm::Result SampledSdm::monodromy(const System& sys, Propagators& cache, double axial_mm, int ticks,
                                         Eigen::MatrixXd* phi_out) const {
  const Eigen::Index n = sys.a.rows();
  const double period_s = ticks * tick_s_;
  const int k = std::min(
      ticks,
      std::max(settings_.min_grid_per_period,
               static_cast<int>(std::ceil(kTwoPi * sys.highest_mode_hz * period_s / settings_.max_grid_phase_rad))));
  const Eigen::Index dim = n + 2 * (k + 1);
  Result res;
  res.grid.resize(static_cast<std::size_t>(k) + 1);
  for (int j = 0; j <= k; ++j)
    res.grid[static_cast<std::size_t>(j)] = static_cast<int>(std::lround(static_cast<double>(j) * ticks / k));
  auto grid_tick = [&](int q) {  // any grid index, periodic in k
    const int p = q >= 0 ? q / k : -((-q + k - 1) / k);
    return static_cast<double>(res.grid[static_cast<std::size_t>(q - p * k)] + p * ticks);
  };
  // The directional matrix per tick at this depth.
  const DirectionalMatrix directional(cutter_, material_, mode_, radial_mm_, settings_.axial_slices, axial_mm);
  const double dphi = kTwoPi / (cutter_.teeth * ticks);
  const int sub = std::max(2, static_cast<int>(std::ceil(400.0 / ticks)));
  auto power = [&](int m) -> const MatrixXd& {
    auto it = cache.a_pow.find(m);
    if (it == cache.a_pow.end()) {
      MatrixXd p = MatrixXd::Identity(n, n);
      for (int i = 0; i < m; ++i) p = sys.a * p;
      it = cache.a_pow.emplace(m, std::move(p)).first;
    }
    return it->second;
  };
  auto power_b = [&](int r) -> const MatrixXd& {  // A^r B
    if (cache.a_pow_b.empty()) cache.a_pow_b.push_back(sys.b);
    while (static_cast<int>(cache.a_pow_b.size()) <= r) cache.a_pow_b.push_back(sys.a * cache.a_pow_b.back());
    return cache.a_pow_b[static_cast<std::size_t>(r)];
  };
  // Columns: [s_0, g_-1, ..., g_-(k+1)]; rows of each grid value as a function of them.
  MatrixXd x = MatrixXd::Zero(n, dim);
  x.leftCols(n).setIdentity();
  std::vector<MatrixXd> g(static_cast<std::size_t>(k) + 1);
  g[0] = sys.c * x;
  // y += w_i times grid value q: a current one is a 2 x dim row pair; a delayed one is its own history
  // column pair (the identity there), so the product is w_i added to those columns (the same sums).
  auto add_ref = [&](MatrixXd& y, const auto& wi, int q) {
    if (q >= 0)
      y.noalias() += wi * g[static_cast<std::size_t>(q)];
    else
      y.middleCols(n + 2 * (-q - 1), 2) += wi;
  };
  MatrixXd w(n, 12), y(n, dim);
  // The history columns are reached from the oldest: before interval j only g_-(k+1) .. g_-(k-j) have entered
  // (the delayed references) and g_-1 (the first interval's current one), so the columns from n + 2 up to
  // `live` are still zero and the propagator's product skips them (a third of the work at k = 40).
  const Eigen::Index head = n + 2;
  Eigen::Index live = dim;
  for (int j = 0; j < k; ++j) {
    const int first = res.grid[static_cast<std::size_t>(j)], last = res.grid[static_cast<std::size_t>(j) + 1];
    // References: current j-1, j, j+1 (+), delayed j-k-1, j-k, j-k+1 (-): F = K (q - q(t - tau)).
    const int refs[6] = {j - 1, j, j + 1, j - k - 1, j - k, j - k + 1};
    // w = sum over the interval's ticks l of A^(last - 1 - l) B K_l [cur(l), -del(l)]: each tick's rank-2 input
    // through its propagator A^r B (n x 2), not the n x 12 sum through A at every tick.
    w.setZero();
    bool any = false;
    for (int l = first; l < last; ++l) {
      const Eigen::Matrix2d kl = directional.mean(l * dphi, dphi, sub);
      if (kl.isZero(0.0)) continue;
      const double t = l + 0.5;
      const Eigen::Vector3d cur = lagrange(grid_tick(j - 1), grid_tick(j), grid_tick(j + 1), t);
      const Eigen::Vector3d del = lagrange(grid_tick(j - k - 1), grid_tick(j - k), grid_tick(j - k + 1), t - ticks);
      Eigen::Matrix<double, 2, 12> input;
      for (int i = 0; i < 3; ++i) {
        input.middleCols<2>(2 * i) = cur(i) * kl;
        input.middleCols<2>(6 + 2 * i) = -del(i) * kl;
      }
      w.noalias() += power_b(last - 1 - l) * input;
      any = true;
    }
    const MatrixXd& propagator = power(last - first);
    y.leftCols(head).noalias() = propagator * x.leftCols(head);
    if (live < dim) y.rightCols(dim - live).noalias() = propagator * x.rightCols(dim - live);
    y.middleCols(head, live - head).setZero();
    live = std::max(head, std::min(live, n + 2 * static_cast<Eigen::Index>(std::max(0, k - j - 2))));
    if (any) {
      for (int i : {0, 1, 3, 4, 5}) add_ref(y, w.middleCols(2 * i, 2), refs[i]);
      const MatrixXd wu = w.middleCols(4, 2);
      const Eigen::Matrix2d m = Eigen::Matrix2d::Identity() - sys.c * wu;
      const MatrixXd next = m.partialPivLu().solve(sys.c * y);
      x = y + wu * next;
      if (j + 1 < k) g[static_cast<std::size_t>(j) + 1] = next;
    } else {
      x = y;
      if (j + 1 < k) g[static_cast<std::size_t>(j) + 1] = sys.c * x;
    }
  }
  MatrixXd phi = MatrixXd::Zero(dim, dim);
  phi.topRows(n) = x;
  for (int m = 1; m <= k; ++m) phi.middleRows(n + 2 * (m - 1), 2) = g[static_cast<std::size_t>(k - m)];
  phi.block(n + 2 * k, n, 2, 2).setIdentity();  // g'_-(k+1) = g_-1
  res.mu = cache.dominant(phi);
  if (phi_out) *phi_out = std::move(phi);
  return res;
}

double SampledSdm::chatter_hz(const Result& r, int ticks) const {
  // History entry q (q = 1 .. k) is the grid point k - q of the last period.
  const auto k = static_cast<int>(r.history.size() / 2);
  std::vector<double> t(static_cast<std::size_t>(k));
  for (int q = 1; q <= k; ++q)
    t[static_cast<std::size_t>(q - 1)] = static_cast<double>(r.grid[static_cast<std::size_t>(k - q)] - ticks) / ticks;
  return floquet_chatter_hz(r.mu, t, r.history, 1.0 / (ticks * tick_s_));
}

SampledSdm::AtSpeed::AtSpeed(const SampledSdm& sdm, double rpm)
    : sdm_(&sdm),
      ticks_(sdm.ticks_per_tooth(rpm)),
      rpm_(sdm.stepped_rpm(rpm)),
      sys_(sdm.per_speed_ ? sdm.system_at(rpm_) : sdm.base_) {}

SampledSdm::AtSpeed SampledSdm::at(double rpm) const { return AtSpeed(*this, rpm); }

std::complex<double> SampledSdm::AtSpeed::multiplier(double axial_mm) {
  if (!(axial_mm > 0.0) || !std::isfinite(axial_mm))
    throw std::invalid_argument("axial depth = " + fmt(axial_mm) + " mm: must be > 0 and finite");
  cache_.dominant = DominantMultiplier{};
  return sdm_->monodromy(sys_, cache_, axial_mm, ticks_).mu;
}

SdmPoint SampledSdm::AtSpeed::critical(double guess_mm, double rel_tol, double first_step) {
  cache_.dominant = DominantMultiplier{};
  // The last unstable depth's matrix and result (the bracket's hi at the end): its critical mode's vector
  // gives the chatter frequency without forming the matrix again.
  MatrixXd phi, phi_hi;
  Result hi;
  const DepthBracket br = find_critical_depth(
      [&](double b) {
        Result r = sdm_->monodromy(sys_, cache_, b, ticks_, &phi);
        const double ln_mu = std::log(std::abs(r.mu));
        if (ln_mu >= 0.0) phi_hi.swap(phi), hi = std::move(r);
        return ln_mu;
      },
      guess_mm, rel_tol, first_step);
  SdmPoint p;
  p.rpm = rpm_;
  p.critical_depth_mm = br.lo_mm;
  if (!std::isfinite(br.hi_mm)) {
    p.critical_depth_mm = br.hi_mm;
    return p;
  }
  const auto k = static_cast<Eigen::Index>(hi.grid.size()) - 1;
  hi.history = eigenvector_for(phi_hi, hi.mu).segment(sys_.a.rows(), 2 * k);
  p.type = hi.mu.real() < 0.0 && std::abs(hi.mu.imag()) < 1e-3 * std::abs(hi.mu) ? CutClass::kFlip : CutClass::kHopf;
  p.chatter_hz = sdm_->chatter_hz(hi, ticks_);
  return p;
}

std::complex<double> SampledSdm::multiplier(double axial_mm, double rpm) const { return at(rpm).multiplier(axial_mm); }

SdmPoint SampledSdm::critical(double rpm, double guess_mm, double rel_tol) const {
  return at(rpm).critical(guess_mm, rel_tol);
}

}  // namespace robodamp::milling
