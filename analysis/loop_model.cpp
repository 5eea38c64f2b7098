// long: the discrete and the continuous loop models share their state-space pieces; splitting them is left for a later pass
#include "analysis/loop_model.hpp"

#include "analysis/gain_path.hpp"
#include "analysis/quiet_command.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "control/controller.hpp"
#include "filters/design.hpp"
#include "filters/harmonic_notch.hpp"
#include "sim_plant/state_space.hpp"
#include "units/units.hpp"

namespace robodamp::analysis {

namespace {

using Eigen::MatrixXd;

// Output of `first` feeds `second`.
DiscreteSs series(const DiscreteSs& first, const DiscreteSs& second) {
  const Eigen::Index n1 = first.a.rows(), n2 = second.a.rows();
  DiscreteSs s;
  s.a = MatrixXd::Zero(n1 + n2, n1 + n2);
  s.a.topLeftCorner(n1, n1) = first.a;
  s.a.bottomLeftCorner(n2, n1) = second.b * first.c;
  s.a.bottomRightCorner(n2, n2) = second.a;
  s.b = MatrixXd(n1 + n2, first.b.cols());
  s.b << first.b, second.b * first.d;
  s.c = MatrixXd(second.c.rows(), n1 + n2);
  s.c << second.d * first.c, second.c;
  s.d = second.d * first.d;
  return s;
}

DiscreteSs delay_line(int samples) {
  DiscreteSs s;
  s.a = MatrixXd::Zero(samples, samples);
  for (int i = 1; i < samples; ++i) s.a(i, i - 1) = 1.0;
  s.b = MatrixXd::Zero(samples, 1);
  s.b(0, 0) = 1.0;
  s.c = MatrixXd::Zero(1, samples);
  s.c(0, samples - 1) = 1.0;
  s.d = MatrixXd::Zero(1, 1);
  return s;
}

// One TDF-II section: y = b0 x + s1; s1' = b1 x - a1 y + s2; s2' = b2 x - a2 y.
DiscreteSs section_ss(const filters::BiquadCoefficients& q, double scale) {
  DiscreteSs s;
  s.a = (MatrixXd(2, 2) << -q.a1, 1.0, -q.a2, 0.0).finished();
  s.b = (MatrixXd(2, 1) << (q.b1 - q.a1 * q.b0) * scale, (q.b2 - q.a2 * q.b0) * scale).finished();
  s.c = (MatrixXd(1, 2) << 1.0, 0.0).finished();
  s.d = (MatrixXd(1, 1) << q.b0 * scale).finished();
  return s;
}

}  // namespace

LoopModel::LoopModel(const config::Config& cfg, std::optional<double> spindle_rpm)
    : cfg_(cfg),
      plant_(sim::build_plant_model(cfg)),
      chain_(control::design_chain(cfg)),
      sensor_model_(cfg.sensor, cfg.loop.rate_hz, 0),
      sensor_(plant_.index_of(cfg.sensor.location)) {
  const double t = 1.0 / cfg.loop.rate_hz;
  // The harmonic notches at this speed, fully faded in, as the chain runs them: the designed controller's
  // own settings and the bank's rule of which are on (filters/harmonic_notch.hpp).
  if (spindle_rpm && chain_.params.harmonic_notch.enabled) {
    const auto& n = chain_.params.harmonic_notch;
    spindle_rpm_ = *spindle_rpm;
    const double tooth_hz = *spindle_rpm * cfg.spindle.teeth / 60.0;
    const int on = filters::HarmonicNotchBank::steady_count(n, tooth_hz, cfg.loop.rate_hz);
    for (int k = 1; k <= on; ++k) {
      const double f = k * tooth_hz;
      if (chain_.params.sections.count >= filters::kMaxSections)
        throw std::invalid_argument("the chain and the harmonic notches need more than " +
                                    std::to_string(filters::kMaxSections) + " second-order sections");
      const auto c = filters::HarmonicNotchBank::design(f, std::min(n.bandwidth_hz, f), n.depth_db, cfg.loop.rate_hz);
      chain_.params.sections.sections[chain_.params.sections.count++] = c;
      notches_.sections[notches_.count++] = c;
    }
  }
  const auto& ss = plant_.ss;
  const Eigen::Index nu = ss.b.cols(), nl = static_cast<Eigen::Index>(plant_.locations.size());
  const sim::DelayedZoh coil = sim::discretise_zoh_delayed(ss.a, ss.b.leftCols(1), t, plant_.actuator.delay_s);
  const sim::Zoh forces = sim::discretise_zoh(ss.a, ss.b.rightCols(nu - 1), t);
  phi_ = coil.phi;
  gamma_late_ = coil.gamma_late;
  gamma_early_ = coil.gamma_early;
  gamma_force_ = forces.gamma;
  delay_steps_ = coil.steps;
  c_accel_ = ss.c.middleRows(2 * nl, nl);
  d_accel_coil_ = ss.d.block(2 * nl, 0, nl, 1);
  d_accel_force_ = ss.d.block(2 * nl, 1, nl, nl);
  Eigen::MatrixXd inputs(phi_.rows(), 2 + nl);
  inputs << gamma_late_, gamma_early_, gamma_force_;
  resolvent_ = Resolvent(phi_, inputs, c_accel_);

  open_loop_unit_ = open_loop({});
}

DiscreteSs LoopModel::open_loop(const std::vector<std::size_t>& forces_at) const {
  // Controller output -> (computation delay + actuator delay) -> plant -> sensor -> chain (unit K). With
  // force locations, the plant keeps the last held force at each as a state too: the sampled acceleration
  // feels it directly (the same left limit as the coil drive's, plant_response).
  DiscreteSs plant;  // input w[k] = coil drive, state [x; w[k-1] (; f_i[k-1] ...)], output sampled acceleration
  const Eigen::Index n = phi_.rows(), extra = 1 + static_cast<Eigen::Index>(forces_at.size());
  plant.a = MatrixXd::Zero(n + extra, n + extra);
  plant.a.topLeftCorner(n, n) = phi_;
  plant.a.block(0, n, n, 1) = gamma_early_;
  plant.b = MatrixXd::Zero(n + extra, 1);
  plant.b.topRows(n) = gamma_late_;
  plant.b(n, 0) = 1.0;
  plant.c = MatrixXd::Zero(1, n + extra);
  plant.c.leftCols(n) = c_accel_.row(static_cast<Eigen::Index>(sensor_));
  plant.c(0, n) = d_accel_coil_(static_cast<Eigen::Index>(sensor_), 0);
  plant.d = MatrixXd::Zero(1, 1);
  for (std::size_t i = 0; i < forces_at.size(); ++i)
    plant.c(0, n + 1 + static_cast<Eigen::Index>(i)) =
        d_accel_force_(static_cast<Eigen::Index>(sensor_), static_cast<Eigen::Index>(forces_at[i]));
  DiscreteSs sensor;
  if (sensor_model_.has_highpass()) {
    const double g = sensor_model_.highpass_gain(), p = sensor_model_.highpass_pole();
    sensor = {MatrixXd::Constant(1, 1, p), MatrixXd::Constant(1, 1, g * (p - 1.0)), MatrixXd::Constant(1, 1, 1.0),
              MatrixXd::Constant(1, 1, g)};
  } else {
    sensor = {MatrixXd::Zero(0, 0), MatrixXd::Zero(0, 1), MatrixXd::Zero(1, 0), MatrixXd::Constant(1, 1, 1.0)};
  }
  DiscreteSs o = series(series(delay_line(1 + delay_steps_), plant), sensor);
  const auto& sos = chain_.params.sections;
  for (std::size_t i = 0; i < sos.count; ++i) {
    const double scale = i == 0 ? chain_.params.sections_gain / chain_.params.actuator_constant_n_per_v : 1.0;
    o = series(o, section_ss(sos.sections[i], scale));
  }
  return o;
}

SampledPath LoopModel::sampled_path(std::size_t location, double gain, int polarity) const {
  const SampledPaths m = sampled_paths({location}, gain, polarity);
  return {m.a, m.b.col(0), m.c.row(0)};
}

SampledPaths LoopModel::sampled_paths(const std::vector<std::size_t>& locations, double gain, int polarity) const {
  for (const std::size_t l : locations)
    if (l >= plant_.locations.size()) throw std::invalid_argument("LoopModel::sampled_paths: no such location");
  const DiscreteSs o = open_loop(locations);
  const Eigen::Index n = phi_.rows(), plant_at = 1 + delay_steps_;  // the delay line's states come first
  const auto m = static_cast<Eigen::Index>(locations.size());
  SampledPaths p;
  p.a = o.a + (polarity * gain) * o.b * o.c;
  p.b = MatrixXd::Zero(o.a.rows(), m);
  p.c = MatrixXd::Zero(m, o.a.rows());
  for (Eigen::Index i = 0; i < m; ++i) {
    const std::size_t l = locations[static_cast<std::size_t>(i)];
    p.b.col(i).segment(plant_at, n) = gamma_force_.col(static_cast<Eigen::Index>(l));
    p.b(plant_at + n + 1 + i, i) = 1.0;
    p.c.row(i).segment(plant_at, n) = plant_.ss.c.row(static_cast<Eigen::Index>(plant_.output_displacement(l)));
  }
  return p;
}

Complex LoopModel::notch_response(double f_hz) const {
  if (notches_.count == 0) return 1.0;
  const std::vector<filters::BiquadCoefficients> v(notches_.sections.begin(),
                                                   notches_.sections.begin() + static_cast<std::ptrdiff_t>(notches_.count));
  return filters::digital_response(v, 1.0, f_hz, cfg_.loop.rate_hz);
}

Complex LoopModel::feedback_continuous(double f_hz, double gain, int polarity) const {
  const Complex s(0.0, kTwoPi * f_hz);
  return polarity * gain / chain_.params.actuator_constant_n_per_v * chain_.filters_analog(f_hz) * notch_response(f_hz) *
         plant_.actuator.n_per_v(f_hz) * sensor_model_.analog_response(f_hz) * s * s;
}

Complex LoopModel::loop_continuous(double f_hz, double gain, int polarity) const {
  return -feedback_continuous(f_hz, gain, polarity) * plant_.receptance(sensor_, actuator_location(), f_hz);
}

Complex LoopModel::open_continuous(std::size_t g, std::size_t h, double f_hz) const {
  return plant_.receptance(g, h, f_hz);
}

Complex LoopModel::closed_with_feedback(std::size_t g, std::size_t h, double f_hz, Complex q) const {
  const std::size_t a = actuator_location();
  return plant_.receptance(g, h, f_hz) + plant_.receptance(g, a, f_hz) * q * plant_.receptance(sensor_, h, f_hz) /
                                             (1.0 - q * plant_.receptance(sensor_, a, f_hz));
}

Complex LoopModel::closed_continuous(std::size_t g, std::size_t h, double f_hz, double gain, int polarity) const {
  return closed_with_feedback(g, h, f_hz, feedback_continuous(f_hz, gain, polarity));
}

Complex LoopModel::feedback_sampled(double f_hz, double gain, int polarity) const {
  const Complex s(0.0, kTwoPi * f_hz);
  const double period_s = 1.0 / cfg_.loop.rate_hz;
  const Complex delay = std::exp(-s * period_s);  // the command computed at tick k is applied from k + 1
  const Complex zoh = f_hz > 0.0 ? (1.0 - delay) / (s * period_s) : Complex(1.0);
  return polarity * gain / chain_.params.actuator_constant_n_per_v * chain_.filters_digital(f_hz) * delay * zoh *
         plant_.actuator.n_per_v(f_hz) * sensor_model_.analog_response(f_hz) * s * s;
}

Complex LoopModel::closed_sampled(std::size_t g, std::size_t h, double f_hz, double gain, int polarity) const {
  return closed_with_feedback(g, h, f_hz, feedback_sampled(f_hz, gain, polarity));
}

PlantResponse LoopModel::plant_response(double f_hz) const {
  const Eigen::Index nl = static_cast<Eigen::Index>(plant_.locations.size());
  const Complex zi = std::exp(Complex(0.0, -kTwoPi * f_hz / cfg_.loop.rate_hz));  // z^-1
  const Eigen::MatrixXcd r = resolvent_(1.0 / zi);  // the late and early coil inputs, then the forces
  Eigen::MatrixXcd y(nl, 1 + nl);
  y.col(0) = r.col(0) + r.col(1) * zi;
  y.rightCols(nl) = r.rightCols(nl);
  const Complex delay = std::pow(zi, delay_steps_);
  PlantResponse p;
  p.f_hz = f_hz;
  p.accel_per_volt.resize(static_cast<std::size_t>(nl));
  p.accel_per_force.assign(static_cast<std::size_t>(nl), std::vector<Complex>(static_cast<std::size_t>(nl)));
  for (Eigen::Index g = 0; g < nl; ++g) {
    p.accel_per_volt[static_cast<std::size_t>(g)] = (y(g, 0) + d_accel_coil_(g, 0) * zi) * delay;
    for (Eigen::Index h = 0; h < nl; ++h)
      p.accel_per_force[static_cast<std::size_t>(g)][static_cast<std::size_t>(h)] = y(g, 1 + h) + d_accel_force_(g, h) * zi;
  }
  return p;
}

namespace {
// Volts per m/s^2 of sampled acceleration that the controller commands, with the computation delay.
Complex discrete_feedback(const PlantResponse& p, Complex filters, double gain, int polarity, double fs, double t_n_per_v,
                          Complex sensor) {
  const Complex zi = std::exp(Complex(0.0, -kTwoPi * p.f_hz / fs));
  return zi * (polarity * gain / t_n_per_v) * filters * sensor;
}
}  // namespace

Complex LoopModel::loop_discrete(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q = discrete_feedback(p, filters, gain, polarity, cfg_.loop.rate_hz, chain_.params.actuator_constant_n_per_v,
                                     sensor_model_.response(p.f_hz));
  return -q * p.accel_per_volt[sensor_];
}

Complex LoopModel::loop_discrete(double f_hz, double gain, int polarity) const {
  return loop_discrete(plant_response(f_hz), chain_filters_digital(f_hz), gain, polarity);
}

Complex LoopModel::open_discrete(const PlantResponse& p, std::size_t g, std::size_t h) const {
  const double w = kTwoPi * p.f_hz;
  return p.accel_per_force[g][h] / (-w * w);
}

Complex LoopModel::closed_discrete(const PlantResponse& p, Complex filters, std::size_t g, std::size_t h, double gain,
                                   int polarity) const {
  const Complex q = discrete_feedback(p, filters, gain, polarity, cfg_.loop.rate_hz, chain_.params.actuator_constant_n_per_v,
                                      sensor_model_.response(p.f_hz));
  const Complex a = p.accel_per_force[g][h] +
                    p.accel_per_volt[g] * q * p.accel_per_force[sensor_][h] / (1.0 - q * p.accel_per_volt[sensor_]);
  const double w = kTwoPi * p.f_hz;
  return a / (-w * w);
}

Complex LoopModel::command_per_force(const PlantResponse& p, Complex filters, std::size_t h, double gain,
                                     int polarity) const {
  const Complex q = discrete_feedback(p, filters, gain, polarity, cfg_.loop.rate_hz, chain_.params.actuator_constant_n_per_v,
                                      sensor_model_.response(p.f_hz));
  return q * p.accel_per_force[sensor_][h] / (1.0 - q * p.accel_per_volt[sensor_]);
}

Complex LoopModel::command_per_sensor_noise(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q_noise = discrete_feedback(p, filters, gain, polarity, cfg_.loop.rate_hz,
                                           chain_.params.actuator_constant_n_per_v, 1.0);
  const Complex q = q_noise * sensor_model_.response(p.f_hz);
  return q_noise / (1.0 - q * p.accel_per_volt[sensor_]);
}

Complex LoopModel::command_per_open_accel(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q = discrete_feedback(p, filters, gain, polarity, cfg_.loop.rate_hz, chain_.params.actuator_constant_n_per_v,
                                     sensor_model_.response(p.f_hz));
  return q / (1.0 - q * p.accel_per_volt[sensor_]);
}

Eigen::MatrixXd LoopModel::closed_loop_matrix(double gain, int polarity) const {
  const DiscreteSs& o = open_loop_unit_;
  return o.a + (polarity * gain) * o.b * o.c;  // o.d = 0: the delays make the loop strictly causal
}

Eigen::VectorXcd LoopModel::closed_loop_poles(double gain, int polarity) const {
  return Eigen::EigenSolver<Eigen::MatrixXd>(closed_loop_matrix(gain, polarity), false).eigenvalues();
}

double LoopModel::spectral_radius(double gain, int polarity) const {
  return closed_loop_poles(gain, polarity).cwiseAbs().maxCoeff();
}

double turns(const std::function<Complex(double)>& fn, double lo, double hi) {
  const int n0 = 4096;
  std::vector<double> grid(n0 + 1);
  for (int i = 0; i <= n0; ++i) grid[static_cast<std::size_t>(i)] = lo + (hi - lo) * i / n0;
  return turns(fn, grid);
}

double turns(const std::function<Complex(double)>& fn, const std::vector<double>& grid) {
  // Subdivide until each piece turns by less than 0.2 rad and moves by less than a fifth of its distance
  // from the origin (so no whole turn can hide between two samples near a sharp resonance).
  struct Piece {
    double f0, f1;
    Complex v0, v1;
    int depth;
  };
  double total = 0.0;
  std::vector<Piece> stack;
  Complex prev = fn(grid.front());
  for (std::size_t i = 1; i < grid.size(); ++i) {
    const Complex v1 = fn(grid[i]);
    stack.push_back({grid[i - 1], grid[i], prev, v1, 0});
    prev = v1;
    while (!stack.empty()) {
      Piece p = stack.back();
      stack.pop_back();
      const double d = std::arg(p.v1 / p.v0);
      const bool small = std::abs(d) < 0.2 && std::abs(p.v1 - p.v0) < 0.2 * std::min(std::abs(p.v0), std::abs(p.v1));
      if (small || p.depth > 40) {
        total += d;
        continue;
      }
      const double fm = 0.5 * (p.f0 + p.f1);
      const Complex vm = fn(fm);
      stack.push_back({fm, p.f1, vm, p.v1, p.depth + 1});
      stack.push_back({p.f0, fm, p.v0, vm, p.depth + 1});
    }
  }
  return total / kTwoPi;
}

int LoopModel::nyquist_encirclements(double gain, int polarity) const {
  // Over the upper half of the unit circle; the lower half mirrors it.
  const double t = turns([&](double f) { return 1.0 + loop_discrete(f, gain, polarity); }, 0.0, 0.5 * loop_rate_hz());
  return -static_cast<int>(std::lround(2.0 * t));
}

std::vector<double> linear_grid(double lo, double hi, double step) {
  std::vector<double> g;
  const auto n = static_cast<std::size_t>(std::ceil((hi - lo) / step));
  for (std::size_t i = 0; i <= n; ++i) g.push_back(std::min(hi, lo + static_cast<double>(i) * step));
  return g;
}

Peak find_peak(const std::vector<double>& grid, const std::vector<double>& v, const std::function<double(double)>& refine) {
  Peak best{grid.front(), v.front()};
  const std::size_t n = grid.size();
  for (std::size_t i = 0; i < n; ++i) {
    const bool local = (i == 0 || v[i] >= v[i - 1]) && (i + 1 == n || v[i] >= v[i + 1]);
    if (!local || v[i] < 0.5 * best.magnitude) continue;
    Peak p{grid[i], v[i]};
    if (i > 0 && i + 1 < n) {  // golden-section search between the neighbours
      const double r = 0.5 * (std::sqrt(5.0) - 1.0);
      double a = grid[i - 1], b = grid[i + 1];
      double c = b - r * (b - a), d = a + r * (b - a), fc = refine(c), fd = refine(d);
      for (int it = 0; it < 40 && b - a > 1e-7; ++it) {
        if (fc > fd) {
          b = d, d = c, fd = fc, c = b - r * (b - a), fc = refine(c);
        } else {
          a = c, c = d, fc = fd, d = a + r * (b - a), fd = refine(d);
        }
      }
      const double fm = 0.5 * (a + b), vm = refine(fm);
      if (vm > p.magnitude) p = {fm, vm};
    }
    if (p.magnitude > best.magnitude) best = p;
  }
  return best;
}

std::optional<double> max_stable_gain(const LoopModel& m, int polarity) {
  const GainPath path(m.open_loop_unit());  // the poles at ~140 gains: the Hessenberg reduction once
  const auto stable = [&](double k) { return path.spectral_radius(k, polarity) < 1.0; };
  const double k_max = control::kMaxGainNsPerM;
  double lo = 0.0, hi = 0.0;
  const int n = 120;  // log scan 1 .. k_max N s/m
  for (int i = 0; i <= n; ++i) {
    const double k = std::pow(k_max, static_cast<double>(i) / n);
    if (!stable(k)) {
      hi = k;
      break;
    }
    lo = k;
  }
  if (hi == 0.0) return std::nullopt;
  while (hi - lo > 1e-6 * hi) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Margins margins(const LoopModel& m, double gain, int polarity, std::optional<double> max_gain) {
  Margins r;
  if (max_gain) r.gain_margin_db = 20.0 * std::log10(*max_gain / gain);
  // Log grid over (0.1 Hz, Nyquist), crossings refined by bisection.
  const double lo = 0.1, hi = 0.499 * m.loop_rate_hz();
  const int n = 6000;
  auto f_at = [&](int i) { return lo * std::pow(hi / lo, static_cast<double>(i) / n); };
  auto loop = [&](double f) { return m.loop_discrete(f, gain, polarity); };
  Complex prev = loop(f_at(0));
  double best_phase_cross_gap = std::numeric_limits<double>::infinity();
  for (int i = 1; i <= n; ++i) {
    const double f0 = f_at(i - 1), f1 = f_at(i);
    const Complex cur = loop(f1);
    if ((std::abs(prev) - 1.0) * (std::abs(cur) - 1.0) < 0.0) {
      double a = f0, b = f1;
      const bool rising = std::abs(prev) < 1.0;
      for (int it = 0; it < 60; ++it) {
        const double c = 0.5 * (a + b);
        ((std::abs(loop(c)) < 1.0) == rising ? a : b) = c;
      }
      const double fc = 0.5 * (a + b);
      const double arg_deg = std::arg(loop(fc)) * 180.0 / M_PI;
      // Angular distance of L from -1 at the crossover, and the extra lag (a pure delay turns L
      // clockwise) that would bring it there.
      const double pm = 180.0 - std::abs(arg_deg);
      const double lag_deg = std::fmod(arg_deg + 180.0 + 360.0, 360.0);
      if (!r.phase_margin_deg || pm < *r.phase_margin_deg) r.phase_margin_deg = pm, r.gain_crossover_hz = fc;
      const double dm = lag_deg * M_PI / 180.0 / (kTwoPi * fc) * 1e3;
      if (!r.delay_margin_ms || dm < *r.delay_margin_ms) r.delay_margin_ms = dm;
    }
    if (prev.imag() * cur.imag() < 0.0 && cur.real() < 0.0) {
      double a = f0, b = f1;  // refine the crossing of the negative real axis
      const bool from_above = prev.imag() > 0.0;
      for (int it = 0; it < 60; ++it) {
        const double c = 0.5 * (a + b);
        ((loop(c).imag() > 0.0) == from_above ? a : b) = c;
      }
      const double fp = 0.5 * (a + b);
      const double gap = std::abs(std::log(std::abs(loop(fp))));
      if (gap < best_phase_cross_gap) best_phase_cross_gap = gap, r.phase_crossover_hz = fp;
    }
    prev = cur;
  }
  return r;
}

std::vector<FrfResult> improvements(const LoopModel& m, double gain, int polarity, bool discrete) {
  const auto& cfg = m.config();
  const std::vector<double> grid = linear_grid(cfg.analysis.band_min_hz, cfg.analysis.band_max_hz, 0.02);
  std::vector<PlantResponse> pr;
  std::vector<Complex> filt;
  if (discrete)
    for (double f : grid) pr.push_back(m.plant_response(f)), filt.push_back(m.chain_filters_digital(f));
  std::vector<FrfResult> out;
  for (const auto& f : cfg.robot.frfs) {
    FrfResult r;
    r.name = f.name;
    r.response = m.plant().index_of(f.response_location);
    r.excitation = m.plant().index_of(f.excitation_location);
    auto open = [&](double fr) {
      return discrete ? std::abs(m.open_discrete(m.plant_response(fr), r.response, r.excitation))
                      : std::abs(m.open_continuous(r.response, r.excitation, fr));
    };
    auto closed = [&](double fr) {
      return discrete ? std::abs(m.closed_discrete(m.plant_response(fr), m.chain_filters_digital(fr), r.response,
                                                   r.excitation, gain, polarity))
                      : std::abs(m.closed_continuous(r.response, r.excitation, fr, gain, polarity));
    };
    std::vector<double> vo, vc;
    for (std::size_t i = 0; i < grid.size(); ++i) {
      if (discrete) {
        vo.push_back(std::abs(m.open_discrete(pr[i], r.response, r.excitation)));
        vc.push_back(std::abs(m.closed_discrete(pr[i], filt[i], r.response, r.excitation, gain, polarity)));
      } else {
        vo.push_back(open(grid[i]));
        vc.push_back(closed(grid[i]));
      }
    }
    const Peak po = find_peak(grid, vo, open), pc = find_peak(grid, vc, closed);
    r.open_peak_m_per_n = po.magnitude;
    r.open_peak_freq_hz = po.freq_hz;
    r.closed_peak_m_per_n = pc.magnitude;
    r.peak_freq_hz = pc.freq_hz;
    r.improvement_pct = (po.magnitude / pc.magnitude - 1.0) * 100.0;
    out.push_back(r);
  }
  return out;
}

std::vector<SweepPoint> gain_sweep(const LoopModel& m, int polarity, const std::vector<double>& gains) {
  const auto& cfg = m.config();
  const std::vector<double> grid = linear_grid(cfg.analysis.band_min_hz, cfg.analysis.band_max_hz, 0.05);
  std::vector<PlantResponse> pr;
  std::vector<Complex> filt;
  for (double f : grid) pr.push_back(m.plant_response(f)), filt.push_back(m.chain_filters_digital(f));
  std::vector<SweepPoint> out;
  const double fs = m.loop_rate_hz();
  for (double k : gains) {
    SweepPoint p;
    p.gain_ns_per_m = k;
    const Eigen::VectorXcd poles = m.closed_loop_poles(k, polarity);
    p.spectral_radius = poles.cwiseAbs().maxCoeff();
    p.least_damping_ratio = std::numeric_limits<double>::infinity();
    for (const Complex& z : poles) {
      if (std::abs(z) < 1e-9) continue;  // pure delays
      const Complex s = std::log(z) * fs;
      const double wn = std::abs(s), hz = wn / kTwoPi;
      if (hz < 0.5 || hz > 0.25 * fs || s.imag() <= 0.0) continue;
      const double zeta = -s.real() / wn;
      if (zeta < p.least_damping_ratio) p.least_damping_ratio = zeta, p.least_damped_hz = hz;
    }
    for (const auto& f : cfg.robot.frfs) {
      const std::size_t g = m.plant().index_of(f.response_location), h = m.plant().index_of(f.excitation_location);
      double open = 0.0, closed = 0.0;
      for (std::size_t i = 0; i < grid.size(); ++i) {
        open = std::max(open, std::abs(m.open_discrete(pr[i], g, h)));
        closed = std::max(closed, std::abs(m.closed_discrete(pr[i], filt[i], g, h, k, polarity)));
      }
      p.improvement_pct.push_back((open / closed - 1.0) * 100.0);
    }
    out.push_back(std::move(p));
  }
  return out;
}

AnalysisResult analyse(const LoopModel& m) {
  return analyse(m, m.config().controller.gain_ns_per_m, m.config().controller.polarity);
}

std::vector<ModePhase> mode_phases(const LoopModel& m, double gain, int polarity) {
  std::vector<ModePhase> out;
  const sim::FrfPath* loop_path = m.plant().path(m.sensor_location(), m.actuator_location());
  for (const auto& mode : loop_path->modes) {
    const double f = mode.wn_rad_per_s / kTwoPi;
    const Complex c = -m.feedback_continuous(f, gain, polarity) / Complex(0.0, kTwoPi * f);  // -F / v
    out.push_back({f, std::arg(c) * 180.0 / M_PI, c.real() > 0.0});
  }
  return out;
}

AnalysisResult analyse(const LoopModel& m, double gain, int polarity) {
  AnalysisResult r;
  r.gain_ns_per_m = gain;
  r.polarity = polarity;
  r.spectral_radius = m.spectral_radius(gain, polarity);
  r.stable = r.spectral_radius < 1.0;
  r.nyquist_encirclements = m.nyquist_encirclements(gain, polarity);
  if ((r.nyquist_encirclements == 0) != r.stable) {
    std::ostringstream os;
    os << "Nyquist count (" << r.nyquist_encirclements << ") and closed-loop poles (spectral radius "
       << r.spectral_radius << ") disagree: the pole test is taken";
    r.notes.push_back(os.str());
  }
  const double hi = std::max(1e4, 10.0 * m.loop_rate_hz());
  // From just above 0 Hz: the ideal integrator block alone is singular at s = 0 (its product is not).
  const double t = turns([&](double f) { return 1.0 + m.loop_continuous(f, gain, polarity); }, 1e-6, hi);
  r.stable_continuous = std::lround(2.0 * t) == 0;
  r.max_stable_gain_ns_per_m = max_stable_gain(m, polarity);
  r.margins = margins(m, gain, polarity, r.max_stable_gain_ns_per_m);

  r.modes = mode_phases(m, gain, polarity);
  const sim::FrfPath* loop_path = m.plant().path(m.sensor_location(), m.actuator_location());
  double dominant = 0.0, dominant_mag = -1.0;
  for (const auto& mode : r.modes) {
    const double mag = std::abs(loop_path->receptance(mode.freq_hz));
    if (mag > dominant_mag) dominant_mag = mag, dominant = mode.freq_hz;
  }
  const Complex c_plus = -m.feedback_continuous(dominant, gain, 1) / Complex(0.0, kTwoPi * dominant);
  r.recommended_polarity = c_plus.real() > 0.0 ? 1 : -1;
  {
    std::ostringstream os;
    os.precision(3);
    os << "at the dominant mode " << dominant << " Hz the feedback force with polarity +1 is at "
       << std::arg(c_plus) * 180.0 / M_PI << " deg from -velocity: "
       << (r.recommended_polarity == 1 ? "inside" : "outside") << " the damping window (-90, 90) deg";
    r.polarity_reason = os.str();
  }
  if (r.recommended_polarity != polarity)
    r.notes.push_back("controller.polarity = " + std::to_string(polarity) + " does not damp the dominant mode; " +
                      "the analysis recommends " + std::to_string(r.recommended_polarity));
  r.frfs_continuous = improvements(m, gain, polarity, false);
  r.frfs_discrete = improvements(m, gain, polarity, true);
  if (r.stable) {
    const QuietCommand q = quiet_command(m, gain, polarity);
    r.quiet_command_rms_v = q.rms_v, r.quiet_command_peak_hz = q.peak_density_hz;
    const double floor_v = m.config().supervision.instability_floor_v;
    if (floor_v > 0.0 && 3.0 * q.rms_v > floor_v) {
      std::ostringstream os;
      os.precision(3);
      os << "the command on a quiet cell is " << q.rms_v << " V RMS (most of it near " << q.peak_density_hz
         << " Hz), above a third of supervision.instability_floor_v = " << floor_v
         << " V: its swells can trip the instability detector on a stable loop; retune, or raise the floor to at least "
         << 3.0 * q.rms_v << " V";
      r.notes.push_back(os.str());
    }
  }
  for (const auto& n : m.plant().notes) r.notes.push_back(n);
  return r;
}

}  // namespace robodamp::analysis
