#include "identify/modal_fit.hpp"
#include "measfiles/table.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "analysis/spectral.hpp"
#include "identify/modal_fit_detail.hpp"
#include "identify/numeric_csv.hpp"

namespace robodamp::identify {

namespace detail {

// The refinement's relative error counts |H| as at least this fraction of the band's peak: at a deep
// antiresonance an H1 estimate's relative error is large (low coherence, leakage of the drive
// vibration), and a pure relative weight would let those few points pull every residue.
constexpr double kAntiresonanceFloor = 0.05;

// LSCF at one order: the common denominator A(W) = sum a_j W^j (a_p = 1) with W = e^{-i w dt}, fitted with
// the numerator by linear least squares on B(W_k) - H_k A(W_k) = 0; the poles are A's roots.
std::vector<Pole> lscf_poles(const std::vector<double>& f, const std::vector<Complex>& h, int p, double dt, double f_lo,
                             double f_hi) {
  const auto k = static_cast<Eigen::Index>(f.size());
  Eigen::MatrixXd a(2 * k, 2 * p + 1);
  Eigen::VectorXd rhs(2 * k);
  for (Eigen::Index r = 0; r < k; ++r) {
    const Complex w = std::polar(1.0, -kTwoPi * f[static_cast<std::size_t>(r)] * dt);
    const Complex hk = h[static_cast<std::size_t>(r)];
    Complex wj(1.0);
    for (int j = 0; j <= p; ++j) {
      a(2 * r, j) = wj.real(), a(2 * r + 1, j) = wj.imag();  // numerator b_j
      if (j < p) {
        const Complex c = -hk * wj;  // denominator a_j
        a(2 * r, p + 1 + j) = c.real(), a(2 * r + 1, p + 1 + j) = c.imag();
      } else {
        const Complex c = hk * wj;  // a_p = 1 on the right-hand side
        rhs(2 * r) = c.real(), rhs(2 * r + 1) = c.imag();
      }
      wj *= w;
    }
  }
  const Eigen::VectorXd norms = a.colwise().norm().cwiseMax(1e-300);
  const Eigen::VectorXd x =
      (a * norms.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(rhs).cwiseQuotient(norms);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(p, p);  // monic: W^p + a_{p-1} W^{p-1} + ... + a_0
  for (int j = 0; j < p; ++j) companion(0, j) = -x(p + 1 + (p - 1 - j));
  for (int j = 1; j < p; ++j) companion(j, j - 1) = 1.0;
  const Eigen::VectorXcd roots = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  std::vector<Pole> out;
  for (Eigen::Index i = 0; i < roots.size(); ++i) {
    if (std::abs(roots(i)) < 1e-12) continue;
    const Complex s = -std::log(roots(i)) / dt;
    const Pole q{s};
    if (s.imag() > 0.0 && s.real() < 0.0 && q.freq_hz() >= f_lo && q.freq_hz() <= f_hi && q.damping() < 0.5)
      out.push_back(q);
  }
  std::sort(out.begin(), out.end(), [](const Pole& x1, const Pole& x2) { return x1.freq_hz() < x2.freq_hz(); });
  return out;
}

// LSFD: residues of the given poles with lower (1 / (i w)^2) and upper (constant) residual terms.
// weight_floor > 0: each row divided by max(|H|, weight_floor) (relative error, for wide bands whose
// magnitude spans decades); 0: absolute error.
void lsfd(const std::vector<double>& f, const std::vector<Complex>& h, const std::vector<Pole>& poles, ModalFit& fit,
          double weight_floor) {
  const auto k = static_cast<Eigen::Index>(f.size()), m = static_cast<Eigen::Index>(poles.size());
  const Eigen::Index unknowns = 2 * m + 4;
  Eigen::MatrixXd a(2 * k, unknowns);
  Eigen::VectorXd y(2 * k);
  auto basis = [&](double f_hz, Eigen::Index col) -> Complex {
    const Complex s(0.0, kTwoPi * f_hz);
    if (col < 2 * m) {
      const Complex lam = poles[static_cast<std::size_t>(col / 2)].s;
      const Complex p1 = 1.0 / (s - lam), p2 = 1.0 / (s - std::conj(lam));
      return col % 2 == 0 ? p1 + p2 : Complex(0.0, 1.0) * (p1 - p2);  // sigma_re, sigma_im
    }
    const Complex lower = 1.0 / (s * s);
    switch (col - 2 * m) {
      case 0:
        return lower;
      case 1:
        return Complex(0.0, 1.0) * lower;
      case 2:
        return 1.0;
      default:
        return Complex(0.0, 1.0);
    }
  };
  for (Eigen::Index r = 0; r < k; ++r) {
    const Complex hr = h[static_cast<std::size_t>(r)];
    const double wgt = weight_floor > 0.0 ? 1.0 / std::max(std::abs(hr), weight_floor) : 1.0;
    for (Eigen::Index c = 0; c < unknowns; ++c) {
      const Complex b = basis(f[static_cast<std::size_t>(r)], c) * wgt;
      a(2 * r, c) = b.real(), a(2 * r + 1, c) = b.imag();
    }
    y(2 * r) = hr.real() * wgt, y(2 * r + 1) = hr.imag() * wgt;
  }
  const Eigen::VectorXd norms = a.colwise().norm().cwiseMax(1e-300);
  const Eigen::VectorXd x = (a * norms.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(y).cwiseQuotient(norms);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Pole& q = poles[static_cast<std::size_t>(i)];
    IdentifiedMode md;
    md.natural_freq_hz = q.freq_hz();
    md.damping_ratio = q.damping();
    md.residue_re = x(2 * i), md.residue_im = x(2 * i + 1);
    const double wn = std::abs(q.s), wd = q.s.imag(), mag = std::hypot(md.residue_re, md.residue_im);
    md.stiffness_n_per_m = mag > 0.0 ? wn * wn / (2.0 * mag * wd) : INFINITY;
    fit.modes.push_back(md);
  }
  fit.lower_residual = {x(2 * m), x(2 * m + 1)};
  fit.upper_residual = {x(2 * m + 2), x(2 * m + 3)};
  double err = 0.0, ref = 0.0;
  for (Eigen::Index r = 0; r < k; ++r) {
    Complex model(0.0);
    for (Eigen::Index c = 0; c < unknowns; ++c) model += x(c) * basis(f[static_cast<std::size_t>(r)], c);
    fit.fitted.push_back(model);
    fit.fitted_f_hz.push_back(f[static_cast<std::size_t>(r)]);
    err += std::norm(model - h[static_cast<std::size_t>(r)]);
    ref += std::norm(h[static_cast<std::size_t>(r)]);
  }
  fit.fit_error_pct = ref > 0.0 ? 100.0 * std::sqrt(err / ref) : 0.0;
}

// The model's value at f: sum over modes of sigma/(s - lam) + conj, plus lower/(s^2) and upper residuals.
Complex model_at(double f_hz, const std::vector<IdentifiedMode>& modes, Complex lower, Complex upper) {
  const Complex s(0.0, kTwoPi * f_hz);
  Complex h = lower / (s * s) + upper;
  for (const auto& m : modes) {
    const double wn = kTwoPi * m.natural_freq_hz, z = m.damping_ratio;
    const Complex lam(-z * wn, wn * std::sqrt(std::max(1.0 - z * z, 1e-12))), sig(m.residue_re, m.residue_im);
    h += sig / (s - lam) + std::conj(sig) / (s - std::conj(lam));
  }
  return h;
}

// Nonlinear least squares (Levenberg-Marquardt, Eigen) of every mode's frequency, damping and residue and
// the residual terms, from the LSCF/LSFD estimate, on the relative error (noise proportional to |H|, as an
// H1 estimate's is): it removes the bias the linearised LSCF has under noise.
struct Refinement {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  const std::vector<double>* f;
  const std::vector<Complex>* h;
  std::size_t modes;
  double sigma_scale, lower_scale, upper_scale;
  double floor;  // the relative error's denominator never drops below this (deep antiresonances)
  [[nodiscard]] int inputs() const { return static_cast<int>(4 * modes + 4); }
  [[nodiscard]] int values() const { return static_cast<int>(2 * f->size()); }
  [[nodiscard]] std::vector<IdentifiedMode> unpack(const Eigen::VectorXd& x, Complex& lower, Complex& upper) const {
    std::vector<IdentifiedMode> out(modes);
    for (std::size_t i = 0; i < modes; ++i) {
      const auto k = static_cast<Eigen::Index>(4 * i);
      out[i].natural_freq_hz = x(k);
      out[i].damping_ratio = x(k + 1) * 1e-2;
      out[i].residue_re = x(k + 2) * sigma_scale, out[i].residue_im = x(k + 3) * sigma_scale;
    }
    const auto k = static_cast<Eigen::Index>(4 * modes);
    lower = {x(k) * lower_scale, x(k + 1) * lower_scale};
    upper = {x(k + 2) * upper_scale, x(k + 3) * upper_scale};
    return out;
  }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    Complex lower, upper;
    const auto m = unpack(x, lower, upper);
    for (std::size_t i = 0; i < f->size(); ++i) {
      const Complex e = (model_at((*f)[i], m, lower, upper) - (*h)[i]) / std::max(std::abs((*h)[i]), floor);
      r(static_cast<Eigen::Index>(2 * i)) = e.real(), r(static_cast<Eigen::Index>(2 * i + 1)) = e.imag();
    }
    return 0;
  }
};

void refine(const std::vector<double>& f, const std::vector<Complex>& h, ModalFit& fit) {
  double sigma_scale = 0.0;
  for (const auto& m : fit.modes) sigma_scale = std::max(sigma_scale, std::hypot(m.residue_re, m.residue_im));
  if (!(sigma_scale > 0.0)) return;
  const double w_lo = kTwoPi * f.front(), w_hi = kTwoPi * f.back();
  double peak = 0.0;
  for (const Complex& v : h) peak = std::max(peak, std::abs(v));
  Refinement fn{&f,
                &h,
                fit.modes.size(),
                sigma_scale,
                sigma_scale * w_lo,
                sigma_scale / w_hi,
                std::max(kAntiresonanceFloor * peak, 1e-300)};
  Eigen::VectorXd x(fn.inputs());
  for (std::size_t i = 0; i < fit.modes.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(4 * i);
    x(k) = fit.modes[i].natural_freq_hz, x(k + 1) = fit.modes[i].damping_ratio * 1e2;
    x(k + 2) = fit.modes[i].residue_re / sigma_scale, x(k + 3) = fit.modes[i].residue_im / sigma_scale;
  }
  const auto k = static_cast<Eigen::Index>(4 * fit.modes.size());
  x(k) = fit.lower_residual.real() / fn.lower_scale, x(k + 1) = fit.lower_residual.imag() / fn.lower_scale;
  x(k + 2) = fit.upper_residual.real() / fn.upper_scale, x(k + 3) = fit.upper_residual.imag() / fn.upper_scale;
  Eigen::NumericalDiff<Refinement> diff(fn);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Refinement>> lm(diff);
  lm.parameters.maxfev = 200 * (fn.inputs() + 1);
  lm.minimize(x);
  Complex lower, upper;
  std::vector<IdentifiedMode> modes = fn.unpack(x, lower, upper);
  for (std::size_t i = 0; i < modes.size(); ++i) {
    // Keep the refinement only while it stays physical (a mode in the band, damped).
    if (!(modes[i].damping_ratio > 0.0 && modes[i].damping_ratio < 0.5 && modes[i].natural_freq_hz >= f.front() &&
          modes[i].natural_freq_hz <= f.back()))
      return;
    const double wn = kTwoPi * modes[i].natural_freq_hz, wd = wn * std::sqrt(1.0 - std::pow(modes[i].damping_ratio, 2));
    const double mag = std::hypot(modes[i].residue_re, modes[i].residue_im);
    modes[i].stiffness_n_per_m = mag > 0.0 ? wn * wn / (2.0 * mag * wd) : INFINITY;
  }
  fit.modes = modes;
  fit.lower_residual = lower, fit.upper_residual = upper;
  double err = 0.0, ref = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    fit.fitted[i] = model_at(f[i], fit.modes, lower, upper);
    err += std::norm(fit.fitted[i] - h[i]), ref += std::norm(h[i]);
  }
  fit.fit_error_pct = 100.0 * std::sqrt(err / ref);
}

void usable_points(const FrfData& d, const ModalFitSettings& s, std::vector<double>& f, std::vector<Complex>& h) {
  if (d.f_hz.size() != d.h.size() || (!d.coherence.empty() && d.coherence.size() != d.h.size()))
    throw std::invalid_argument("the FRF's columns have different lengths");
  for (std::size_t i = 0; i < d.h.size(); ++i) {
    if (!std::isfinite(d.f_hz[i]) || !std::isfinite(d.h[i].real()) || !std::isfinite(d.h[i].imag()))
      throw std::invalid_argument("row " + std::to_string(i + 1) + ": a value is not a finite number");
    const bool in_band = (s.band_hi_hz <= 0.0) || (d.f_hz[i] >= s.band_lo_hz && d.f_hz[i] <= s.band_hi_hz);
    const bool coherent = d.coherence.empty() || d.coherence[i] >= s.min_coherence;
    if (in_band && coherent && d.f_hz[i] > 0.0) f.push_back(d.f_hz[i]), h.push_back(d.h[i]);
  }
  if (f.size() < 20)
    throw std::invalid_argument("too few coherent points in the band: " + std::to_string(f.size()) +
                                " (at least 20 with coherence >= " + std::to_string(s.min_coherence) + ")");
}

PoleSelection stable_poles(const std::function<std::vector<Pole>(int)>& poles_at_order, const ModalFitSettings& s,
                           std::vector<StabilisationPoint>& diagram) {
  // The stabilisation diagram: a pole is stable when the order below has one close to it in frequency and
  // damping; the chain of such orders counts how long it has stayed. A second chain with the damping's
  // tolerance relaxed keeps the columns whose damping scatters under noise (one of a close pair, whose
  // linearised estimate wanders while its frequency holds): candidates the fit must justify.
  std::vector<Pole> previous, last;
  std::vector<int> previous_chain, previous_loose, last_chain, last_loose;
  for (int p = 2; p <= s.max_order; p += 2) {
    const std::vector<Pole> poles = poles_at_order(p);
    std::vector<int> chain(poles.size(), 0), loose(poles.size(), 0);
    for (std::size_t i = 0; i < poles.size(); ++i) {
      for (std::size_t j = 0; j < previous.size(); ++j) {
        const double df = std::abs(poles[i].freq_hz() - previous[j].freq_hz()) / poles[i].freq_hz();
        const double dz = std::abs(poles[i].damping() - previous[j].damping()) / std::max(poles[i].damping(), 1e-6);
        if (df >= s.stable_freq) continue;
        if (dz < s.stable_damping) chain[i] = std::max(chain[i], previous_chain[j] + 1);
        if (dz < kLooseStableDamping) loose[i] = std::max(loose[i], previous_loose[j] + 1);
      }
      diagram.push_back({p, poles[i].freq_hz(), poles[i].damping(), chain[i] > 0});
    }
    previous = poles, previous_chain = chain, previous_loose = loose;
    last = poles, last_chain = chain, last_loose = loose;
  }
  PoleSelection out;
  auto near = [](const std::vector<Pole>& set, const Pole& q, double rel) {
    return std::any_of(set.begin(), set.end(),
                       [&](const Pole& c) { return std::abs(c.freq_hz() - q.freq_hz()) < rel * q.freq_hz(); });
  };
  for (std::size_t i = 0; i < last.size(); ++i)
    if (last_chain[i] >= s.stable_orders && !near(out.stable, last[i], 2e-3)) out.stable.push_back(last[i]);
  for (std::size_t i = 0; i < last.size(); ++i)
    if (last_chain[i] < s.stable_orders && last_loose[i] >= s.stable_orders &&
        !near(out.stable, last[i], s.stable_freq) && !near(out.candidates, last[i], s.stable_freq))
      out.candidates.push_back(last[i]);
  if (out.stable.empty())
    throw std::invalid_argument("no pole stays put over " + std::to_string(s.stable_orders) +
                                " orders in the band: raise the maximum order, widen the band or check the data");
  return out;
}

std::vector<Pole> with_supported_candidates(const PoleSelection& selection,
                                            const std::function<double(const std::vector<Pole>&)>& fit_error) {
  std::vector<Pole> poles = selection.stable;
  double error = fit_error(poles);
  for (const Pole& c : selection.candidates) {
    std::vector<Pole> more = poles;
    more.push_back(c);
    std::sort(more.begin(), more.end(), [](const Pole& a, const Pole& b) { return a.freq_hz() < b.freq_hz(); });
    const double e = fit_error(more);
    if (e < kCandidateErrorRatio * error) poles = std::move(more), error = e;
  }
  return poles;
}

// One band: LSCF poles over the stabilisation diagram, LSFD residues, the refinement.
ModalFit fit_band(const std::vector<double>& f, const std::vector<Complex>& h, const ModalFitSettings& s) {
  ModalFit fit;
  fit.band_lo_hz = f.front(), fit.band_hi_hz = f.back();
  const double dt = 1.0 / (2.0 * f.back());
  const PoleSelection selection =
      stable_poles([&](int p) { return lscf_poles(f, h, p, dt, fit.band_lo_hz, fit.band_hi_hz); }, s, fit.diagram);
  auto fitted = [&](const std::vector<Pole>& poles) {
    ModalFit trial;
    trial.band_lo_hz = fit.band_lo_hz, trial.band_hi_hz = fit.band_hi_hz;
    lsfd(f, h, poles, trial);
    refine(f, h, trial);
    return trial;
  };
  const std::vector<Pole> chosen = selection.candidates.empty()
                                       ? selection.stable
                                       : with_supported_candidates(selection, [&](const std::vector<Pole>& poles) {
                                           return fitted(poles).fit_error_pct;
                                         });
  ModalFit out = fitted(chosen);
  out.diagram = std::move(fit.diagram);
  return out;
}

// A band spanning decades (the robot SLE study's robot: 46 modes from 8 Hz to 6.6 kHz). One LSCF over it needs a
// high order, is slow and ill-conditioned at the low end, so it is cut into sub-bands (a frequency ratio
// of at least kSubBandRatio and at least kSubBandPoints points, overlapping by kSubBandOverlap on each
// side), each fitted as a band of its own with its residual terms standing for the rest; a sub-band keeps
// the modes in its core (its own share, without the overlap). The residues of all of them then come from
// one LSFD over the whole band, weighted to relative error.
constexpr double kSubBandRatio = 2.0;
constexpr std::size_t kSubBandPoints = 80;
constexpr double kSubBandOverlap = 1.4;
constexpr std::size_t kSubBandMaxPoints = 600;
constexpr std::size_t kWideLsfdMaxPoints = 6000;
constexpr double kSubBandStableDamping = 0.2;

std::vector<std::size_t> thinned(std::size_t begin, std::size_t end, std::size_t max_points) {
  std::vector<std::size_t> idx;
  const std::size_t stride = std::max<std::size_t>(1, (end - begin + max_points - 1) / max_points);
  for (std::size_t i = begin; i < end; i += stride) idx.push_back(i);
  return idx;
}

ModalFit fit_wide_band(const std::vector<double>& f, const std::vector<Complex>& h, const ModalFitSettings& s) {
  // Core edges.
  std::vector<std::size_t> edges{0};
  while (edges.back() < f.size() - 1) {
    std::size_t j = edges.back();
    while (j < f.size() - 1 && (f[j] < kSubBandRatio * f[edges.back()] || j - edges.back() < kSubBandPoints)) ++j;
    if (f.size() - 1 - j < kSubBandPoints) j = f.size() - 1;  // no short tail: it joins this band
    edges.push_back(j);
  }
  ModalFitSettings sub = s;
  sub.max_order = s.max_order;
  sub.stable_damping = std::max(s.stable_damping, kSubBandStableDamping);
  std::vector<Pole> poles;
  ModalFit fit;
  fit.band_lo_hz = f.front(), fit.band_hi_hz = f.back();
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
    const double core_lo = f[edges[b]], core_hi = f[edges[b + 1]];
    const auto lo =
        static_cast<std::size_t>(std::lower_bound(f.begin(), f.end(), core_lo / kSubBandOverlap) - f.begin());
    const auto hi =
        static_cast<std::size_t>(std::upper_bound(f.begin(), f.end(), core_hi * kSubBandOverlap) - f.begin());
    std::vector<double> fb;
    std::vector<Complex> hb;
    for (std::size_t i : thinned(lo, hi, kSubBandMaxPoints)) fb.push_back(f[i]), hb.push_back(h[i]);
    ModalFit part;
    try {
      part = fit_band(fb, hb, sub);
    } catch (const std::invalid_argument&) {
      continue;  // no mode stays put here
    }
    for (const auto& p : part.diagram) fit.diagram.push_back(p);
    const bool last = b + 2 == edges.size();
    for (const auto& m : part.modes)
      if (m.natural_freq_hz >= core_lo && (m.natural_freq_hz < core_hi || last)) {
        const double wn = kTwoPi * m.natural_freq_hz;
        poles.push_back({Complex(-m.damping_ratio * wn, wn * std::sqrt(1.0 - m.damping_ratio * m.damping_ratio))});
      }
  }
  if (poles.empty())
    throw std::invalid_argument("no pole stays put in any sub-band: raise the maximum order or check the data");
  std::vector<double> fa;
  std::vector<Complex> ha;
  double peak = 0.0;
  for (std::size_t i : thinned(0, f.size(), kWideLsfdMaxPoints)) fa.push_back(f[i]), ha.push_back(h[i]);
  for (const Complex& v : ha) peak = std::max(peak, std::abs(v));
  lsfd(fa, ha, poles, fit, std::max(1e-6 * peak, 1e-300));
  double err = 0.0, ref = 0.0;
  for (std::size_t i = 0; i < fa.size(); ++i) err += std::norm(fit.fitted[i] - ha[i]), ref += std::norm(ha[i]);
  fit.fit_error_pct = 100.0 * std::sqrt(err / ref);
  return fit;
}

}  // namespace detail

using namespace detail;

Complex fitted_receptance(const ModalFit& fit, double f_hz) {
  return model_at(f_hz, fit.modes, fit.lower_residual, fit.upper_residual);
}

ModalFit fit_modes(const FrfData& d, const ModalFitSettings& s) {
  if (d.f_hz.size() != d.h.size() || (!d.coherence.empty() && d.coherence.size() != d.h.size()))
    throw std::invalid_argument("the FRF's columns have different lengths");
  if (s.max_order < 4 || s.max_order > 200 || s.max_order % 2 != 0)
    throw std::invalid_argument("max order = " + std::to_string(s.max_order) + ": allowed an even 4 <= value <= 200");
  std::vector<double> f;
  std::vector<Complex> h;
  usable_points(d, s, f, h);
  if (f.back() / f.front() > s.wide_band_ratio) return fit_wide_band(f, h, s);
  return fit_band(f, h, s);
}

FrfData read_frf_csv(const std::string& path, FrfKind kind) {
  const std::string prefix = "freq_hz,re_m_per_n,im_m_per_n";
  const measfiles::Table t = measfiles::read_table(path);
  const bool with_coherence =
      t.names.empty() ? t.columns >= 4 : t.names.size() >= 4 && measfiles::normalised(t.names[3]) == "coherence";
  const NumericCsv csv = read_numeric_csv(path, prefix, prefix + "[,coherence]", with_coherence ? 4 : 3);
  FrfData d;
  for (const auto& v : csv.rows) {
    const Complex s(0.0, kTwoPi * v[0]);
    Complex h(v[1], v[2]);
    if (kind == FrfKind::kMobility) h = v[0] > 0.0 ? h / s : Complex(0.0);
    if (kind == FrfKind::kAccelerance) h = v[0] > 0.0 ? h / (s * s) : Complex(0.0);
    d.f_hz.push_back(v[0]), d.h.push_back(h);
    if (with_coherence) d.coherence.push_back(v[3]);
  }
  return d;
}

FrfData frf_from_time_series_csv(const std::string& path, FrfKind kind, double segment_s, double overlap,
                                 double max_hz) {
  return frf_from_time_series(read_time_series_csv(path, "time_s,force_n,response"), kind, segment_s, overlap, max_hz);
}

FrfData frf_from_time_series(const TimeSeries& ts, FrfKind kind, double segment_s, double overlap, double max_hz) {
  const double fs = ts.fs_hz;
  const std::vector<double>& x = ts.input;
  const std::vector<double>& y = ts.output;
  const auto segment = static_cast<std::size_t>(std::lround(segment_s * fs));
  if (segment < 16 || segment > x.size())
    throw std::invalid_argument("segment of " + std::to_string(segment_s) + " s = " + std::to_string(segment) +
                                " samples: allowed 16 .. the record's " + std::to_string(x.size()));
  const analysis::FrfEstimate e = analysis::welch_frf(x, y, fs, segment, overlap, max_hz);
  FrfData d;
  for (std::size_t k = 1; k < e.f_hz.size(); ++k) {
    const Complex s(0.0, kTwoPi * e.f_hz[k]);
    Complex h = e.h1[k];
    if (kind == FrfKind::kMobility) h /= s;
    if (kind == FrfKind::kAccelerance) h /= s * s;
    d.f_hz.push_back(e.f_hz[k]), d.h.push_back(h), d.coherence.push_back(e.coherence[k]);
  }
  return d;
}

}  // namespace robodamp::identify
