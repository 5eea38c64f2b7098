#include "milling/chatter.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "analysis/fft.hpp"
#include "milling/sdm.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

const char* to_string(CutClass c) {
  switch (c) {
    case CutClass::kStable:
      return "stable";
    case CutClass::kHopf:
      return "hopf";
    case CutClass::kFlip:
      return "flip";
    case CutClass::kOutOfCut:
      return "out_of_cut";
  }
  return "?";
}

namespace {

struct OneSignal {
  double ratio{0.0}, growth{-1e300}, nonharmonic{0.0}, chatter_hz{0.0}, chatter_energy{0.0};
  double persistence{0.0};         // RMS of the differences in the last quarter over the second
  std::complex<double> root{0.0};  // the dominant multiplier's estimate
  Eigen::VectorXcd roots;          // the autoregressive model's roots (root is the largest)
  bool settled{true};
};

double rms(const std::vector<double>& v, std::size_t a, std::size_t b) {
  double s = 0.0;
  for (std::size_t i = a; i < b; ++i) s += v[i] * v[i];
  return b > a ? std::sqrt(s / static_cast<double>(b - a)) : 0.0;
}

// The roots of an autoregressive model of order 4 fitted by least squares to the second half of the
// differences; the largest is the dominant Floquet multiplier, even when several decaying and growing
// components are mixed (a ratio of RMS values is not). Empty when too short or all zero.
Eigen::VectorXcd ar_roots(const std::vector<double>& d) {
  constexpr int p = 4;
  const std::size_t from = d.size() / 2;
  if (d.size() - from < 4 * p) return {};
  const auto rows = static_cast<Eigen::Index>(d.size() - from - p);
  Eigen::MatrixXd a(rows, p);
  Eigen::VectorXd b(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t i = from + p + static_cast<std::size_t>(r);
    b(r) = d[i];
    for (int k = 0; k < p; ++k) a(r, k) = d[i - 1 - static_cast<std::size_t>(k)];
  }
  const double scale = a.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return {};
  const Eigen::VectorXd coef = (a / scale).colPivHouseholderQr().solve(b / scale);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(p, p);
  companion.row(0) = coef.transpose();
  for (int k = 1; k < p; ++k) companion(k, k - 1) = 1.0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
}

std::complex<double> largest(const Eigen::VectorXcd& roots) {
  std::complex<double> out(0.0);
  for (Eigen::Index k = 0; k < roots.size(); ++k)
    if (std::abs(roots(k)) > std::abs(out)) out = roots(k);
  return out;
}

// The dominant Floquet mode's shape over one period, from every phase s of the period: its part of the
// differences d_s(k) = x(start + s + (k+1) N) - x(start + s + k N) is Re(q(s) mu^k), with
// q(s) = C mu^(s/N) (mu - 1) p(s) and p the mode's periodic factor. q(s) by least squares over the last half
// of the periods, the autoregressive model's other roots fitted beside it (the decaying transients of other
// modes, which the spectrum cannot tell from the chatter). Returns q(s), s = 0 .. N - 1 (empty if no fit).
Eigen::VectorXcd floquet_shape(const std::vector<double>& x, std::size_t start, std::size_t n, std::size_t periods,
                               const Eigen::VectorXcd& roots, std::complex<double> mu) {
  // One root of each conjugate pair, the dominant one as mu itself (its conjugate gives the same mode).
  std::vector<std::complex<double>> basis{mu};
  for (Eigen::Index j = 0; j < roots.size(); ++j) {
    const std::complex<double> r = roots(j);
    const bool same = std::abs(r - mu) <= 1e-9 * std::abs(mu) || std::abs(r - std::conj(mu)) <= 1e-9 * std::abs(mu);
    if (!same && r.imag() >= 0.0 && std::abs(r) > 0.0) basis.push_back(r);
  }
  const std::size_t first = periods / 2, rows = periods - 1 - first;
  if (rows < 2 * basis.size() + 4) return {};
  Eigen::MatrixXd a(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(2 * basis.size()));
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t j = 0; j < basis.size(); ++j) {
      // Each column at most 1 in magnitude: a growing root counted back from the last row, a decaying one
      // from the first (a whole column's factor changes q by one constant for every phase, not its shape).
      const double from = std::abs(basis[j]) >= 1.0 ? static_cast<double>(rows - 1) : 0.0;
      const std::complex<double> z = std::pow(basis[j], static_cast<double>(r) - from);
      a(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(2 * j)) = z.real();
      a(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(2 * j + 1)) = z.imag();
    }
  Eigen::MatrixXd b(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(n));
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t s = 0; s < n; ++s) {
      const std::size_t i = start + s + (first + r) * n;
      b(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(s)) = x[i + n] - x[i];
    }
  const Eigen::MatrixXd coef = a.completeOrthogonalDecomposition().solve(b);
  Eigen::VectorXcd q(static_cast<Eigen::Index>(n));
  for (Eigen::Index s = 0; s < q.size(); ++s)
    q(s) = std::complex<double>(coef(0, s), -coef(1, s));  // Re(q z) = a Re z - b Im z
  return q;
}

OneSignal analyse(const std::vector<double>& x, std::size_t start, std::size_t period, std::size_t base, double fs,
                  const ChatterThresholds& t) {
  OneSignal o;
  const std::size_t periods = (x.size() - start) / period;
  if (periods < 8) throw std::invalid_argument("detect_chatter: needs at least 8 periods after the start");
  // Once-per-period samples and their differences.
  std::vector<double> d;
  for (std::size_t i = 0; i + 1 < periods; ++i) d.push_back(x[start + (i + 1) * period] - x[start + i * period]);
  const std::size_t q = d.size() / 4;
  const double r2 = rms(d, q, 2 * q), r4 = rms(d, 3 * q, d.size());
  const std::size_t half = start + (periods / 2) * period, end = start + periods * period;
  double mean = 0.0;
  for (std::size_t i = half; i < end; ++i) mean += x[i];
  mean /= static_cast<double>(end - half);
  double ac = 0.0;
  for (std::size_t i = half; i < end; ++i) ac += (x[i] - mean) * (x[i] - mean);
  ac = std::sqrt(ac / static_cast<double>(end - half));
  double scale = 0.0;
  for (std::size_t i = half; i < end; ++i) scale = std::max(scale, std::abs(x[i]));
  o.ratio = ac > 0.0 ? rms(d, d.size() / 2, d.size()) / ac : 0.0;
  o.settled = r4 <= t.settled_ratio * std::max(scale, 1e-300);
  o.persistence = r2 > 0.0 ? r4 / r2 : 0.0;
  o.roots = ar_roots(d);
  o.root = largest(o.roots);
  o.growth = std::abs(o.root) > 0.0 ? std::log(std::abs(o.root)) : -1e300;
  // Spectrum of the last half (a whole number of harmonic base periods, so the harmonics sit on bins).
  const std::size_t whole = ((end - half) / (period * base)) * period * base;
  if (whole >= 2 * period * base) {
    analysis::RealFft fft(whole);
    for (std::size_t i = 0; i < whole; ++i) fft.input()[i] = x[end - whole + i] - mean;
    const std::complex<double>* X = fft.forward();
    const std::size_t step = whole / (period * base);  // bins between spindle (or tooth) harmonics
    double total = 0.0, off = 0.0, best = 0.0;
    std::size_t best_k = 0;
    for (std::size_t k = 1; k < fft.bins(); ++k) {
      const double e = std::norm(X[k]);
      total += e;
      if (k % step == 0) continue;
      off += e;
      if (e > best) best = e, best_k = k;
    }
    o.nonharmonic = total > 0.0 ? off / total : 0.0;
    o.chatter_hz = static_cast<double>(best_k) * fs / static_cast<double>(whole);
    o.chatter_energy = best;
    // The dominant multiplier fixes the chatter frequency up to whole multiples of the period's frequency:
    // f = k f_p +- arg(mu) / (2 pi) f_p. The candidate with the most energy in the spectrum is the chatter
    // (a large transient of a slow mode elsewhere in the spectrum is not one of them).
    if (std::abs(o.root) > 0.0) {
      const double fp = fs / static_cast<double>(period), df = fs / static_cast<double>(whole);
      const double alias_hz = std::abs(std::arg(o.root)) / (kTwoPi)*fp;
      double best_candidate = -1.0;
      for (std::size_t k = 0; (static_cast<double>(k) + 1.0) * fp <= 0.5 * fs; ++k)
        for (const double f : {static_cast<double>(k) * fp + alias_hz, static_cast<double>(k + 1) * fp - alias_hz}) {
          const auto bin = static_cast<std::size_t>(std::lround(f / df));
          double e = 0.0;
          for (std::size_t b = bin > 0 ? bin - 1 : 1; b <= bin + 1 && b < fft.bins(); ++b)
            if (b % step != 0) e = std::max(e, std::norm(X[b]));
          if (e > best_candidate && f > 0.0) best_candidate = e, o.chatter_hz = f;
        }
    }
  }
  return o;
}

// The chatter frequency of the dominant Floquet mode (multiplier mu) the signals share, as SDM takes it from
// its critical eigenvector: the strongest harmonic of the mode's periodic factor, the x and y displacements'
// energies summed (floquet_chatter_hz). 0 when the mode cannot be fitted.
double shape_chatter_hz(const std::vector<const std::vector<double>*>& signals,
                        const std::vector<Eigen::VectorXcd>& roots, std::size_t start, std::size_t n, double fs,
                        std::complex<double> mu) {
  if (signals.empty() || signals.size() > 2 || !(std::abs(mu) > 0.0)) return 0.0;
  const std::size_t periods = (signals[0]->size() - start) / n;
  Eigen::VectorXcd history = Eigen::VectorXcd::Zero(static_cast<Eigen::Index>(2 * n));
  for (std::size_t c = 0; c < signals.size(); ++c) {
    const Eigen::VectorXcd q = floquet_shape(*signals[c], start, n, periods, roots[c], mu);
    if (q.size() == 0) return 0.0;
    for (std::size_t s = 0; s < n; ++s) history(static_cast<Eigen::Index>(2 * s + c)) = q(static_cast<Eigen::Index>(s));
  }
  std::vector<double> t(n);
  for (std::size_t s = 0; s < n; ++s) t[s] = static_cast<double>(s) / static_cast<double>(n);
  return floquet_chatter_hz(mu, t, history, fs / static_cast<double>(n));
}

}  // namespace

double chatter_family_hz(double chatter_hz, double period_hz) {
  if (!(period_hz > 0.0) || !std::isfinite(chatter_hz)) return chatter_hz;
  const double r = std::fmod(std::abs(chatter_hz), period_hz);
  return std::min(r, period_hz - r);
}

bool same_chatter(double a_hz, double b_hz, double period_hz, double tol_hz) {
  return std::abs(chatter_family_hz(a_hz, period_hz) - chatter_family_hz(b_hz, period_hz)) <= tol_hz;
}

ChatterVerdict detect_chatter(const std::vector<const std::vector<double>*>& signals, std::size_t start,
                              int samples_per_period, int harmonic_base_periods, double fs, double out_of_cut_share,
                              const ChatterThresholds& t) {
  ChatterVerdict v;
  v.out_of_cut_share = out_of_cut_share;
  bool settled = true;
  double chatter_energy = -1.0, persistence = 0.0;
  std::complex<double> root(0.0);
  std::vector<Eigen::VectorXcd> roots;
  v.growth_per_period = -1e300;
  for (const auto* s : signals) {
    const OneSignal o = analyse(*s, start, static_cast<std::size_t>(samples_per_period),
                                static_cast<std::size_t>(std::max(harmonic_base_periods, 1)), fs, t);
    settled = settled && o.settled;
    persistence = std::max(persistence, o.persistence);
    v.once_per_period_ratio = std::max(v.once_per_period_ratio, o.ratio);
    v.nonharmonic_energy_ratio = std::max(v.nonharmonic_energy_ratio, o.nonharmonic);
    if (o.growth > v.growth_per_period) v.growth_per_period = o.growth, root = o.root;
    roots.push_back(o.roots);
    if (o.chatter_energy > chatter_energy) chatter_energy = o.chatter_energy, v.chatter_hz = o.chatter_hz;
  }
  // A cut whose once-per-period samples have settled is periodic, hence stable, even if its edges leave the
  // chip somewhere in each period (a forced periodic loss of contact). Otherwise it chatters when the
  // differences grow (the dominant multiplier's magnitude above 1), or when they persist at a sizeable
  // share of the motion (a limit cycle: chatter bounded by the loss of contact).
  const bool grows = v.growth_per_period > t.growth_per_period + t.neutral_growth;
  const bool persists = persistence >= t.persistence && v.once_per_period_ratio >= t.limit_cycle_ratio;
  const bool out = out_of_cut_share > t.out_of_cut_share;
  v.stable = settled || !(grows || persists);
  if (v.stable) {
    v.classification = v.mechanism = CutClass::kStable;
    v.chatter_hz = 0.0;
    return v;
  }
  // The chatter frequency as SDM defines it (floquet_chatter_hz): the growing Floquet mode's strongest harmonic.
  // The spectrum's strongest candidate stays where the mode cannot be fitted.
  if (const double hz = shape_chatter_hz(signals, roots, start, static_cast<std::size_t>(samples_per_period), fs, root);
      hz > 0.0)
    v.chatter_hz = hz;
  // Period doubling: the dominant multiplier real and negative (within 3 degrees of -1's direction).
  const bool flip = root.real() < 0.0 && std::abs(root.imag()) < t.flip_angle * std::abs(root);
  v.mechanism = flip ? CutClass::kFlip : CutClass::kHopf;
  v.classification = out ? CutClass::kOutOfCut : v.mechanism;
  return v;
}

}  // namespace robodamp::milling
