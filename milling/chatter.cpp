#include "milling/chatter.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "analysis/fft.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

const char* to_string(CutClass c) {
  switch (c) {
    case CutClass::kStable: return "stable";
    case CutClass::kHopf: return "hopf";
    case CutClass::kFlip: return "flip";
    case CutClass::kOutOfCut: return "out_of_cut";
  }
  return "?";
}

namespace {

struct OneSignal {
  double ratio{0.0}, growth{-1e300}, nonharmonic{0.0}, chatter_hz{0.0}, chatter_energy{0.0};
  double persistence{0.0};  // RMS of the differences in the last quarter over the second
  std::complex<double> root{0.0};  // the dominant multiplier's estimate
  bool settled{true};
};

double rms(const std::vector<double>& v, std::size_t a, std::size_t b) {
  double s = 0.0;
  for (std::size_t i = a; i < b; ++i) s += v[i] * v[i];
  return b > a ? std::sqrt(s / static_cast<double>(b - a)) : 0.0;
}

// ln |largest root| of an autoregressive model of order 4 fitted by least squares to the second half of
// the differences: the dominant Floquet multiplier's magnitude, even when several decaying and growing
// components are mixed (a ratio of RMS values is not).
std::complex<double> dominant_root(const std::vector<double>& d) {
  constexpr int p = 4;
  const std::size_t from = d.size() / 2;
  if (d.size() - from < 4 * p) return 0.0;
  const auto rows = static_cast<Eigen::Index>(d.size() - from - p);
  Eigen::MatrixXd a(rows, p);
  Eigen::VectorXd b(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t i = from + p + static_cast<std::size_t>(r);
    b(r) = d[i];
    for (int k = 0; k < p; ++k) a(r, k) = d[i - 1 - static_cast<std::size_t>(k)];
  }
  const double scale = a.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return 0.0;
  const Eigen::VectorXd coef = (a / scale).colPivHouseholderQr().solve(b / scale);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(p, p);
  companion.row(0) = coef.transpose();
  for (int k = 1; k < p; ++k) companion(k, k - 1) = 1.0;
  const Eigen::VectorXcd roots = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  std::complex<double> largest(0.0);
  for (Eigen::Index k = 0; k < roots.size(); ++k)
    if (std::abs(roots(k)) > std::abs(largest)) largest = roots(k);
  return largest;
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
  o.root = dominant_root(d);
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
      const double alias_hz = std::abs(std::arg(o.root)) / (kTwoPi) * fp;
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

}  // namespace

ChatterVerdict detect_chatter(const std::vector<const std::vector<double>*>& signals, std::size_t start,
                              int samples_per_period, int harmonic_base_periods, double fs, double out_of_cut_share,
                              const ChatterThresholds& t) {
  ChatterVerdict v;
  v.out_of_cut_share = out_of_cut_share;
  bool settled = true;
  double chatter_energy = -1.0, persistence = 0.0;
  std::complex<double> root(0.0);
  v.growth_per_period = -1e300;
  for (const auto* s : signals) {
    const OneSignal o = analyse(*s, start, static_cast<std::size_t>(samples_per_period),
                                static_cast<std::size_t>(std::max(harmonic_base_periods, 1)), fs, t);
    settled = settled && o.settled;
    persistence = std::max(persistence, o.persistence);
    v.once_per_period_ratio = std::max(v.once_per_period_ratio, o.ratio);
    v.nonharmonic_energy_ratio = std::max(v.nonharmonic_energy_ratio, o.nonharmonic);
    if (o.growth > v.growth_per_period) v.growth_per_period = o.growth, root = o.root;
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
  // Period doubling: the dominant multiplier real and negative (within 3 degrees of -1's direction).
  const bool flip = root.real() < 0.0 && std::abs(root.imag()) < t.flip_angle * std::abs(root);
  v.mechanism = flip ? CutClass::kFlip : CutClass::kHopf;
  v.classification = out ? CutClass::kOutOfCut : v.mechanism;
  return v;
}

}  // namespace robodamp::milling
