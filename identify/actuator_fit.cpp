#include "identify/actuator_fit.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace robodamp::identify {

namespace {

constexpr int kMinPoints = 8;
constexpr double kDelayGridS = 1e-5;

struct Point {
  double w;
  Complex g;
};

struct Trial {
  double t{0.0}, a1{0.0}, a0{0.0}, tau{0.0};
  double rel_error{INFINITY};
};

// Linear least squares at a fixed delay: unknowns (a1, a0, T), each equation divided by |G s^2|.
Trial solve_at(const std::vector<Point>& pts, double tau) {
  const auto n = static_cast<Eigen::Index>(pts.size());
  Eigen::MatrixXd a(2 * n, 3);
  Eigen::VectorXd b(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Point& p = pts[static_cast<std::size_t>(i)];
    const Complex s(0.0, p.w);
    const double wgt = 1.0 / std::abs(p.g * s * s);
    const Complex c1 = p.g * s, c0 = p.g, ct = -s * s * std::exp(-s * tau), rhs = -p.g * s * s;
    a(2 * i, 0) = c1.real() * wgt, a(2 * i, 1) = c0.real() * wgt, a(2 * i, 2) = ct.real() * wgt;
    a(2 * i + 1, 0) = c1.imag() * wgt, a(2 * i + 1, 1) = c0.imag() * wgt, a(2 * i + 1, 2) = ct.imag() * wgt;
    b(2 * i) = rhs.real() * wgt, b(2 * i + 1) = rhs.imag() * wgt;
  }
  const Eigen::Vector3d x = a.colPivHouseholderQr().solve(b);
  Trial tr{x(2), x(0), x(1), tau, INFINITY};
  if (!(tr.a0 > 0.0 && tr.a1 > 0.0 && tr.t > 0.0)) return tr;
  double err = 0.0, ref = 0.0;
  for (const Point& p : pts) {
    const Complex s(0.0, p.w);
    const Complex m = tr.t * s * s * std::exp(-s * tau) / (s * s + tr.a1 * s + tr.a0);
    err += std::norm((m - p.g) / p.g);
    ref += 1.0;
  }
  tr.rel_error = std::sqrt(err / ref);
  return tr;
}

}  // namespace

ActuatorFit fit_actuator(const ActuatorFrf& frf, const ActuatorFitSettings& s) {
  std::vector<Point> pts;
  for (std::size_t i = 0; i < frf.f_hz.size(); ++i) {
    const double f = frf.f_hz[i];
    if (f < s.band_lo_hz || f > s.band_hi_hz) continue;
    if (!frf.coherence.empty() && !(frf.coherence[i] >= s.min_coherence)) continue;
    const Complex g = frf.n_per_v[i];
    if (!std::isfinite(g.real()) || !std::isfinite(g.imag()))
      throw std::invalid_argument("the actuator FRF has a non-finite value at " + std::to_string(f) + " Hz");
    if (std::abs(g) == 0.0) continue;
    pts.push_back({kTwoPi * f, g});
  }
  if (static_cast<int>(pts.size()) < kMinPoints)
    throw std::invalid_argument("only " + std::to_string(pts.size()) + " points of the actuator FRF lie in " +
                                std::to_string(s.band_lo_hz) + ".." + std::to_string(s.band_hi_hz) +
                                " Hz with coherence >= " + std::to_string(s.min_coherence) + " (at least " +
                                std::to_string(kMinPoints) + " needed)");
  // Delay: grid, then golden section around the best grid point.
  Trial best;
  const int steps = static_cast<int>(std::ceil(s.max_delay_ms * 1e-3 / kDelayGridS));
  for (int k = 0; k <= steps; ++k) {
    const Trial tr = solve_at(pts, k * kDelayGridS);
    if (tr.rel_error < best.rel_error) best = tr;
  }
  if (!std::isfinite(best.rel_error))
    throw std::invalid_argument("no physical actuator model (T, stiffness and damping all positive) fits the FRF in " +
                                std::to_string(s.band_lo_hz) + ".." + std::to_string(s.band_hi_hz) + " Hz");
  double lo = std::max(0.0, best.tau - kDelayGridS), hi = best.tau + kDelayGridS;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 40; ++it) {
    const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    if (solve_at(pts, x1).rel_error < solve_at(pts, x2).rel_error)
      hi = x2;
    else
      lo = x1;
  }
  const Trial refined = solve_at(pts, 0.5 * (lo + hi));
  if (refined.rel_error < best.rel_error) best = refined;

  ActuatorFit fit;
  fit.force_constant_n_per_v = best.t;
  const double wa = std::sqrt(best.a0);
  fit.natural_freq_hz = wa / kTwoPi;
  fit.damping_ratio = best.a1 / (2.0 * wa);
  fit.delay_ms = best.tau * 1e3;
  fit.band_lo_hz = s.band_lo_hz, fit.band_hi_hz = s.band_hi_hz;
  fit.points = static_cast<int>(pts.size());
  double err = 0.0, ref = 0.0;
  for (const Point& p : pts) {
    const double f = p.w / kTwoPi;
    const Complex m =
        filters::actuator_n_per_v(f, fit.force_constant_n_per_v, fit.natural_freq_hz, fit.damping_ratio, best.tau);
    fit.f_hz.push_back(f), fit.measured.push_back(p.g), fit.fitted.push_back(m);
    err += std::norm(m - p.g), ref += std::norm(p.g);
  }
  fit.fit_error_pct = 100.0 * std::sqrt(err / ref);
  return fit;
}

analysis::FrfEstimate periodic_frf(const std::vector<double>& input, const std::vector<double>& output,
                                   std::size_t first, std::size_t period_n, int periods, double fs_hz, double max_hz) {
  if (periods < 1 || first + period_n * static_cast<std::size_t>(periods) > std::min(input.size(), output.size()))
    throw std::invalid_argument("the record holds " + std::to_string(std::min(input.size(), output.size())) +
                                " samples: too few for " + std::to_string(periods) + " periods of " +
                                std::to_string(period_n) + " from sample " + std::to_string(first));
  analysis::FrfAccumulator acc(period_n, fs_hz, 1, analysis::Window::kRectangular, max_hz);
  for (int p = 0; p < periods; ++p) {
    const auto b = static_cast<std::ptrdiff_t>(first + period_n * static_cast<std::size_t>(p));
    acc.add(std::vector<double>(input.begin() + b, input.begin() + b + static_cast<std::ptrdiff_t>(period_n)),
            std::vector<double>(output.begin() + b, output.begin() + b + static_cast<std::ptrdiff_t>(period_n)));
  }
  return acc.result();
}

ActuatorFrf force_per_volt_from_acceleration(const analysis::FrfEstimate& accel_per_volt,
                                             const std::function<Complex(double)>& structure_receptance,
                                             const std::function<Complex(double)>& sensor_response,
                                             double sample_period_s) {
  ActuatorFrf out;
  for (std::size_t i = 0; i < accel_per_volt.f_hz.size(); ++i) {
    const double f = accel_per_volt.f_hz[i];
    if (f <= 0.0) continue;
    const double w = kTwoPi * f, half = 0.5 * w * sample_period_s;
    const Complex hold = std::exp(Complex(0.0, -1.5 * w * sample_period_s)) * (std::sin(half) / half);
    const Complex path = -w * w * structure_receptance(f) * sensor_response(f) * hold;
    out.f_hz.push_back(f);
    out.n_per_v.push_back(accel_per_volt.h1[i] / path);
    out.coherence.push_back(accel_per_volt.coherence[i]);
  }
  return out;
}

}  // namespace robodamp::identify
