#include "identify/common_pole_fit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "identify/modal_fit_detail.hpp"

namespace robodamp::identify {

namespace {

using detail::Pole;

constexpr std::size_t kMaxPointsPerFrf = 500;  // the poles' least squares, thinned evenly

struct Points {
  std::vector<double> f;
  std::vector<Complex> h;
  double weight{1.0};  // 1 / RMS |H|: every FRF counts alike
};

// LSCF at order p with one denominator for all FRFs and a numerator per FRF.
std::vector<Pole> common_lscf_poles(const std::vector<Points>& pts, int p, double dt, double f_lo, double f_hi) {
  Eigen::Index rows = 0;
  for (const auto& q : pts) rows += 2 * static_cast<Eigen::Index>(q.f.size());
  const auto n = static_cast<Eigen::Index>(pts.size());
  const Eigen::Index den0 = n * (p + 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, den0 + p);
  Eigen::VectorXd rhs(rows);
  Eigen::Index r = 0;
  for (Eigen::Index o = 0; o < n; ++o) {
    const Points& q = pts[static_cast<std::size_t>(o)];
    for (std::size_t k = 0; k < q.f.size(); ++k, r += 2) {
      const Complex w = std::polar(1.0, -kTwoPi * q.f[k] * dt);
      const Complex hk = q.h[k] * q.weight;
      Complex wj(q.weight);
      for (int j = 0; j <= p; ++j) {
        a(r, o * (p + 1) + j) = wj.real(), a(r + 1, o * (p + 1) + j) = wj.imag();
        const Complex c = hk * wj / q.weight;
        if (j < p)
          a(r, den0 + j) = -c.real(), a(r + 1, den0 + j) = -c.imag();
        else
          rhs(r) = c.real(), rhs(r + 1) = c.imag();
        wj *= w;
      }
    }
  }
  const Eigen::VectorXd norms = a.colwise().norm().cwiseMax(1e-300);
  const Eigen::VectorXd x =
      (a * norms.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(rhs).cwiseQuotient(norms);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(p, p);
  for (int j = 0; j < p; ++j) companion(0, j) = -x(den0 + (p - 1 - j));
  for (int j = 1; j < p; ++j) companion(j, j - 1) = 1.0;
  const Eigen::VectorXcd roots = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  std::vector<Pole> out;
  for (Eigen::Index i = 0; i < roots.size(); ++i) {
    if (std::abs(roots(i)) < 1e-12) continue;
    const Pole q{-std::log(roots(i)) / dt};
    if (q.s.imag() > 0.0 && q.s.real() < 0.0 && q.freq_hz() >= f_lo && q.freq_hz() <= f_hi && q.damping() < 0.5)
      out.push_back(q);
  }
  std::sort(out.begin(), out.end(), [](const Pole& x1, const Pole& x2) { return x1.freq_hz() < x2.freq_hz(); });
  return out;
}

}  // namespace

std::vector<ModalFit> fit_modes_common(const std::vector<FrfData>& frfs, const ModalFitSettings& s) {
  if (frfs.empty()) throw std::invalid_argument("no FRF to fit");
  if (s.max_order < 4 || s.max_order > 200 || s.max_order % 2 != 0)
    throw std::invalid_argument("max order = " + std::to_string(s.max_order) + ": allowed an even 4 <= value <= 200");
  std::vector<Points> all(frfs.size()), thin(frfs.size());
  double lo = 1e300, hi = 0.0;
  for (std::size_t i = 0; i < frfs.size(); ++i) {
    detail::usable_points(frfs[i], s, all[i].f, all[i].h);
    lo = std::min(lo, all[i].f.front()), hi = std::max(hi, all[i].f.back());
    double ms = 0.0;
    for (const Complex& v : all[i].h) ms += std::norm(v);
    thin[i].weight = 1.0 / std::sqrt(ms / static_cast<double>(all[i].h.size()));
    const std::size_t stride = std::max<std::size_t>(1, (all[i].f.size() + kMaxPointsPerFrf - 1) / kMaxPointsPerFrf);
    for (std::size_t k = 0; k < all[i].f.size(); k += stride)
      thin[i].f.push_back(all[i].f[k]), thin[i].h.push_back(all[i].h[k]);
  }
  if (hi / lo > s.wide_band_ratio)
    throw std::invalid_argument("the band is too wide for one common LSCF: fit the FRFs one by one");
  const double dt = 1.0 / (2.0 * hi);
  std::vector<StabilisationPoint> diagram;
  const detail::PoleSelection selection =
      detail::stable_poles([&](int p) { return common_lscf_poles(thin, p, dt, lo, hi); }, s, diagram);
  auto fitted = [&](const std::vector<Pole>& poles) {
    std::vector<ModalFit> fits;
    for (std::size_t i = 0; i < frfs.size(); ++i) {
      ModalFit fit;
      fit.band_lo_hz = all[i].f.front(), fit.band_hi_hz = all[i].f.back();
      detail::lsfd(all[i].f, all[i].h, poles, fit);
      detail::refine(all[i].f, all[i].h, fit);
      fits.push_back(std::move(fit));
    }
    return fits;
  };
  auto error = [&](const std::vector<Pole>& poles) {  // every FRF's relative error alike
    double sum = 0.0;
    for (const ModalFit& f : fitted(poles)) sum += f.fit_error_pct * f.fit_error_pct;
    return std::sqrt(sum / static_cast<double>(frfs.size()));
  };
  std::vector<ModalFit> out =
      fitted(selection.candidates.empty() ? selection.stable : detail::with_supported_candidates(selection, error));
  for (ModalFit& f : out) f.diagram = diagram;
  return out;
}

}  // namespace robodamp::identify
