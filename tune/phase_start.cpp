#include "tune/phase_start.hpp"

#include <nlopt.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>

#include "analysis/loop_model.hpp"
#include "units/units.hpp"

namespace robodamp::tune {

namespace {

using Complex = std::complex<double>;

struct ModeAt {
  double f_hz{0.0};
  double chain_phase_rad{0.0};  // of -F / v with a unity compensator, polarity +1
};

constexpr unsigned kShapeDims = 6;  // log10 fz, zeta_z, log10 fp, zeta_p, log10 fa, log10 fb
constexpr int kEvaluationsPerStart = 400;
// A compensator 1 % over its gain limit costs as much as an 18 deg phase error at one mode: the limit is
// the search's constraint, the phase only a start.
constexpr double kGainExcessWeight = 1e3;
constexpr double kGainLimitShare = 0.98;  // the penalty starts just inside the limit: a start the search can use

Candidate shape_of(const double* x, int polarity) {
  Candidate c;
  c.fz_hz = std::pow(10.0, x[0]), c.zeta_z = x[1], c.fp_hz = std::pow(10.0, x[2]), c.zeta_p = x[3];
  c.fa_hz = std::pow(10.0, x[4]), c.fb_hz = std::pow(10.0, x[5]);
  c.polarity = polarity;
  return c;
}

std::array<double, kShapeDims> shape_x_of(const Candidate& c) {
  return {std::log10(c.fz_hz), c.zeta_z, std::log10(c.fp_hz), c.zeta_p, std::log10(c.fa_hz), std::log10(c.fb_hz)};
}

double wrapped(double rad) { return std::remainder(rad, 2.0 * std::numbers::pi); }

struct Fit {
  const std::vector<ModeAt>* modes;
  int polarity;
  double match_hz, nyquist_hz, gain_max;
};

// How far the compensator's largest gain from 0.1 Hz to Nyquist, over its gain at the match frequency, is
// above 98 % of gain_max (squared natural log; 0 within it or without a limit): the search's own constraint.
double gain_excess(const Candidate& c, const Fit& fit) {
  if (fit.gain_max <= 0.0) return 0.0;
  const double over =
      std::log(compensator_gain_ratio(c, fit.match_hz, fit.nyquist_hz) / (kGainLimitShare * fit.gain_max));
  return over > 0.0 ? over * over : 0.0;
}

double squared_phase_error(unsigned /*n*/, const double* x, double* /*grad*/, void* data) {
  const auto& fit = *static_cast<const Fit*>(data);
  const Candidate c = shape_of(x, fit.polarity);
  const double flip = fit.polarity < 0 ? std::numbers::pi : 0.0;
  double sum = 0.0;
  for (const ModeAt& m : *fit.modes) {
    const double e = wrapped(m.chain_phase_rad + flip + std::arg(compensator_response(c, m.f_hz)));
    sum += e * e;
  }
  return sum + kGainExcessWeight * gain_excess(c, fit);
}

// Every mode in the band at each plant, with the phase the chain gives it through a unity compensator.
std::vector<ModeAt> modes_in_band(const std::vector<config::Config>& plants, double band_min_hz, double band_max_hz) {
  Candidate unity;  // equal pairs and first-order terms: C = 1
  unity.gain_ns_per_m = 1.0;
  std::vector<ModeAt> out;
  for (const config::Config& plant : plants) {
    if (plant.robot.frfs.empty()) continue;
    const analysis::LoopModel m(with_candidate(plant, unity));
    for (const config::ModeConfig& mode : plant.robot.frfs.front().modes) {
      const double f = mode.natural_freq_hz;
      if (f < band_min_hz || f > band_max_hz) continue;
      const Complex c = -m.feedback_continuous(f, 1.0, 1) / Complex(0.0, kTwoPi * f);
      out.push_back({f, std::arg(c)});
    }
  }
  return out;
}

// Where the fit starts: a unity compensator at the lowest mode, and for each two neighbouring modes of the
// first plant a lightly damped zero pair between them (its phase turns by up to 180 deg across it) with a
// pole pair above the upper one.
std::vector<Candidate> fit_starts(const std::vector<ModeAt>& modes) {
  std::vector<double> f;
  for (const ModeAt& m : modes) f.push_back(m.f_hz);
  std::sort(f.begin(), f.end());
  Candidate unity;
  unity.fz_hz = unity.fp_hz = unity.fa_hz = unity.fb_hz = f.front();
  std::vector<Candidate> out{unity};
  for (std::size_t i = 0; i + 1 < f.size(); ++i) {
    if (f[i + 1] < 1.2 * f[i]) continue;
    Candidate c;
    c.fz_hz = std::sqrt(f[i] * f[i + 1]), c.zeta_z = 0.1;
    c.fp_hz = std::min(kPairMaxHz, 2.0 * f[i + 1]), c.zeta_p = 0.7;
    c.fa_hz = c.fb_hz = f[i];
    out.push_back(c);
  }
  return out;
}

}  // namespace

std::optional<PhaseMatch> phase_matched(const std::vector<config::Config>& plants, double band_min_hz,
                                        double band_max_hz, double compensator_gain_max) {
  const std::vector<ModeAt> modes = modes_in_band(plants, band_min_hz, band_max_hz);
  if (modes.empty()) return std::nullopt;
  const double match_hz = unity_gain_hz(plants.front()), nyquist_hz = 0.5 * plants.front().loop.rate_hz;
  const std::array<double, kShapeDims> lower{std::log10(kPairMinHz),       kZetaMin,
                                             std::log10(kPairMinHz),       kZetaMin,
                                             std::log10(kFirstOrderMinHz), std::log10(kFirstOrderMinHz)};
  const std::array<double, kShapeDims> upper{std::log10(kPairMaxHz),       kZetaMax,
                                             std::log10(kPairMaxHz),       kZetaMax,
                                             std::log10(kFirstOrderMaxHz), std::log10(kFirstOrderMaxHz)};
  std::optional<PhaseMatch> best;
  double best_sum = 0.0;
  for (const int polarity : {1, -1}) {
    Fit fit{&modes, polarity, match_hz, nyquist_hz, compensator_gain_max};
    for (const Candidate& start : fit_starts(modes)) {
      std::array<double, kShapeDims> x = shape_x_of(start);
      for (unsigned i = 0; i < kShapeDims; ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);
      nlopt_opt opt = nlopt_create(NLOPT_LN_NELDERMEAD, kShapeDims);
      nlopt_set_lower_bounds(opt, lower.data());
      nlopt_set_upper_bounds(opt, upper.data());
      nlopt_set_min_objective(opt, squared_phase_error, &fit);
      nlopt_set_maxeval(opt, kEvaluationsPerStart);
      double sum = 0.0;
      (void)nlopt_optimize(opt, x.data(), &sum);  // x holds the best point whatever the return code
      nlopt_destroy(opt);
      sum = squared_phase_error(kShapeDims, x.data(), nullptr, &fit);
      if (best && sum >= best_sum) continue;
      best_sum = sum;
      const Candidate c = shape_of(x.data(), polarity);
      const double phase_sum = sum - kGainExcessWeight * gain_excess(c, fit);
      best = PhaseMatch{c, std::sqrt(phase_sum / static_cast<double>(modes.size())) * 180.0 / std::numbers::pi,
                        static_cast<int>(modes.size())};
    }
  }
  return best;
}

}  // namespace robodamp::tune
