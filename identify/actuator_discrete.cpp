#include "identify/actuator_discrete.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "analysis/loop_model.hpp"
#include "sim_plant/sensor.hpp"
#include "units/units.hpp"

namespace robodamp::identify {

namespace {

constexpr std::size_t kMaxPoints = 160;  // the points matched (evenly thinned from the continuous fit's)
constexpr int kIntervalsBelow = 8;       // sample intervals tried below the continuous fit's delay

// x = (T, fn, 10 zeta, u); the delay lies in one sample interval [n, n + 1) periods, u placing it there.
// The sampled response jumps where the delay crosses a sample instant (the feedthrough part is sampled
// one period later just past it), so each interval is fitted on its own.
double delay_in_interval_s(int n, double u, double period_s) {
  const double frac = std::min(0.5 * (1.0 - std::cos(u)), 1.0 - 1e-6);
  return (n + frac) * period_s;
}

void set_actuator(config::Config& c, const Eigen::VectorXd& x, int n) {
  c.actuator.constant_n_per_v = x(0);
  c.actuator.natural_freq_hz = x(1);
  c.actuator.damping_ratio = x(2) * 1e-1;
  c.actuator.delay_s = delay_in_interval_s(n, x(3), 1.0 / c.loop.rate_hz);
}

Complex recorded(const analysis::LoopModel& m, const sim::Accelerometer& sensor, double f_hz) {
  const analysis::PlantResponse p = m.plant_response(f_hz);
  const double w = kTwoPi * f_hz, t = 1.0 / m.loop_rate_hz();
  return p.accel_per_volt[m.sensor_location()] * sensor.response(f_hz) * std::exp(Complex(0.0, -w * t));
}

struct Residual {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  const config::Config* base;
  int interval;
  const std::vector<double>* f;
  const std::vector<Complex>* measured;
  [[nodiscard]] int inputs() const { return 4; }
  [[nodiscard]] int values() const { return static_cast<int>(2 * f->size()); }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    if (!(x(0) > 0.0 && x(1) > 0.0 && x(2) > 0.0 && x(2) < 10.0)) {  // outside Eq. 3's physical range
      r.setConstant(1e3);
      return 0;
    }
    config::Config c = *base;
    set_actuator(c, x, interval);
    const analysis::LoopModel m(c);
    const sim::Accelerometer sensor(c.sensor, c.loop.rate_hz, 1);
    for (std::size_t i = 0; i < f->size(); ++i) {
      const Complex e = (recorded(m, sensor, (*f)[i]) - (*measured)[i]) / std::abs((*measured)[i]);
      r(static_cast<Eigen::Index>(2 * i)) = e.real(), r(static_cast<Eigen::Index>(2 * i + 1)) = e.imag();
    }
    return 0;
  }
};

}  // namespace

Complex recorded_accel_per_volt(const config::Config& cfg, double f_hz) {
  const analysis::LoopModel m(cfg);
  const sim::Accelerometer sensor(cfg.sensor, cfg.loop.rate_hz, 1);
  return recorded(m, sensor, f_hz);
}

ActuatorFit refine_actuator_discrete(const ActuatorFit& start, const analysis::FrfEstimate& accel_per_volt,
                                     const config::Config& structure) {
  // The measured acceleration per volt at the continuous fit's points, thinned evenly.
  std::vector<double> f;
  std::vector<Complex> measured;
  const std::size_t stride = std::max<std::size_t>(1, (start.f_hz.size() + kMaxPoints - 1) / kMaxPoints);
  std::size_t j = 0;
  for (std::size_t i = 0; i < start.f_hz.size(); i += stride) {
    while (j < accel_per_volt.f_hz.size() && accel_per_volt.f_hz[j] < start.f_hz[i]) ++j;
    if (j == accel_per_volt.f_hz.size()) break;
    f.push_back(accel_per_volt.f_hz[j]), measured.push_back(accel_per_volt.h1[j]);
  }
  // Every interval from no delay up to the one after the continuous fit's: that fit trades its delay
  // against the resonance's frequency and damping and reads it up to several periods long (a true 0.45 ms
  // came out as 0.88 ms), and within one interval the fit runs to the interval's edge when the true delay
  // lies in another.
  const double period_s = 1.0 / structure.loop.rate_hz;
  const int n0 = static_cast<int>(std::floor(start.delay_ms * 1e-3 / period_s));
  Eigen::VectorXd best;
  int best_n = 0;
  double best_norm = INFINITY;
  for (int n = std::max(0, n0 - kIntervalsBelow); n <= n0 + 1; ++n) {
    Residual fn{&structure, n, &f, &measured};
    Eigen::VectorXd x(4);
    x << start.force_constant_n_per_v, start.natural_freq_hz, start.damping_ratio * 1e1, 0.5 * M_PI;
    Eigen::NumericalDiff<Residual> diff(fn);
    Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residual>> lm(diff);
    lm.parameters.maxfev = 200;
    lm.minimize(x);
    if (lm.fnorm < best_norm && x(0) > 0.0 && x(1) > 0.0 && x(2) > 0.0) best_norm = lm.fnorm, best = x, best_n = n;
  }
  if (!std::isfinite(best_norm)) return start;
  const Eigen::VectorXd x = best;

  ActuatorFit out = start;
  out.force_constant_n_per_v = x(0);
  out.natural_freq_hz = x(1);
  out.damping_ratio = x(2) * 1e-1;
  out.delay_ms = delay_in_interval_s(best_n, x(3), period_s) * 1e3;
  // The fit error on the same footing as the continuous fit's: the recorded response against the model's.
  config::Config c = structure;
  set_actuator(c, x, best_n);
  const analysis::LoopModel m(c);
  const sim::Accelerometer sensor(c.sensor, c.loop.rate_hz, 1);
  double err = 0.0, ref = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    err += std::norm(recorded(m, sensor, f[i]) - measured[i]);
    ref += std::norm(measured[i]);
  }
  out.fit_error_pct = 100.0 * std::sqrt(err / ref);
  // The force-per-volt view, for plots: the model's recorded response mapped to force per volt exactly as
  // the measurement was (the continuous fit's factor at each point). Eq. 3 alone would leave out what the
  // sampled loop adds (the hold, the tick of computation, the sensor's coupling): 19 deg at 100 Hz.
  const std::vector<double>& fa = accel_per_volt.f_hz;
  std::size_t k = 0;
  for (std::size_t i = 0; i < out.f_hz.size(); ++i) {
    while (k + 1 < fa.size() && std::abs(fa[k + 1] - out.f_hz[i]) <= std::abs(fa[k] - out.f_hz[i])) ++k;  // nearest bin
    const bool found = !fa.empty() && std::abs(accel_per_volt.h1[k]) > 0.0;
    out.fitted[i] = found ? out.measured[i] / accel_per_volt.h1[k] * recorded(m, sensor, fa[k])
                          : filters::actuator_n_per_v(out.f_hz[i], out.force_constant_n_per_v, out.natural_freq_hz,
                                                      out.damping_ratio, out.delay_ms * 1e-3);
  }
  return out;
}

}  // namespace robodamp::identify
