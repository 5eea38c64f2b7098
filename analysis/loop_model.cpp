// The loop model: its state-space pieces and its responses, continuous and discrete (the analyses on it:
// analysis/loop_analysis.cpp).
#include "analysis/loop_model.hpp"

#include "analysis/gain_path.hpp"
#include "analysis/quiet_command.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>

#include "control/controller.hpp"
#include "filters/design.hpp"
#include "filters/harmonic_notch.hpp"
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
    : LoopModel(cfg, std::make_shared<const SampledPlant>(cfg), spindle_rpm) {}

LoopModel LoopModel::at_speed(double spindle_rpm) const { return {cfg_, s_, spindle_rpm}; }

LoopModel LoopModel::with_controller(const config::Config& cfg) const {
  if (cfg.loop.rate_hz != s_->loop_rate_hz)
    throw std::invalid_argument("LoopModel::with_controller: a controller at " + std::to_string(cfg.loop.rate_hz) +
                                " Hz on a plant sampled at " + std::to_string(s_->loop_rate_hz) + " Hz");
  return {cfg, s_, spindle_rpm_};
}

LoopModel::LoopModel(const config::Config& cfg, std::shared_ptr<const SampledPlant> sampled,
                     std::optional<double> spindle_rpm)
    : cfg_(cfg), s_(std::move(sampled)), chain_(analysis::design_chain(cfg)) {
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
  open_loop_unit_ = open_loop({});
}

DiscreteSs LoopModel::open_loop(const std::vector<std::size_t>& forces_at) const {
  // Controller output -> (computation delay + actuator delay) -> plant -> sensor -> chain (unit K). With
  // force locations, the plant keeps the last held force at each as a state too: the sampled acceleration
  // feels it directly (the same left limit as the coil drive's, plant_response).
  DiscreteSs plant;  // input w[k] = coil drive, state [x; w[k-1] (; f_i[k-1] ...)], output sampled acceleration
  const Eigen::Index n = s_->phi.rows(), extra = 1 + static_cast<Eigen::Index>(forces_at.size());
  plant.a = MatrixXd::Zero(n + extra, n + extra);
  plant.a.topLeftCorner(n, n) = s_->phi;
  plant.a.block(0, n, n, 1) = s_->gamma_early;
  plant.b = MatrixXd::Zero(n + extra, 1);
  plant.b.topRows(n) = s_->gamma_late;
  plant.b(n, 0) = 1.0;
  plant.c = MatrixXd::Zero(1, n + extra);
  plant.c.leftCols(n) = s_->c_accel.row(static_cast<Eigen::Index>(s_->sensor));
  plant.c(0, n) = s_->d_accel_coil(static_cast<Eigen::Index>(s_->sensor), 0);
  plant.d = MatrixXd::Zero(1, 1);
  for (std::size_t i = 0; i < forces_at.size(); ++i)
    plant.c(0, n + 1 + static_cast<Eigen::Index>(i)) =
        s_->d_accel_force(static_cast<Eigen::Index>(s_->sensor), static_cast<Eigen::Index>(forces_at[i]));
  DiscreteSs sensor;
  if (s_->sensor_model.has_highpass()) {
    const double g = s_->sensor_model.highpass_gain(), p = s_->sensor_model.highpass_pole();
    sensor = {MatrixXd::Constant(1, 1, p), MatrixXd::Constant(1, 1, g * (p - 1.0)), MatrixXd::Constant(1, 1, 1.0),
              MatrixXd::Constant(1, 1, g)};
  } else {
    sensor = {MatrixXd::Zero(0, 0), MatrixXd::Zero(0, 1), MatrixXd::Zero(1, 0), MatrixXd::Constant(1, 1, 1.0)};
  }
  DiscreteSs o = series(series(delay_line(1 + s_->delay_steps), plant), sensor);
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
    if (l >= s_->plant.locations.size()) throw std::invalid_argument("LoopModel::sampled_paths: no such location");
  const DiscreteSs o = open_loop(locations);
  const Eigen::Index n = s_->phi.rows(), plant_at = 1 + s_->delay_steps;  // the delay line's states come first
  const auto m = static_cast<Eigen::Index>(locations.size());
  SampledPaths p;
  p.a = o.a + (polarity * gain) * o.b * o.c;
  p.b = MatrixXd::Zero(o.a.rows(), m);
  p.c = MatrixXd::Zero(m, o.a.rows());
  for (Eigen::Index i = 0; i < m; ++i) {
    const std::size_t l = locations[static_cast<std::size_t>(i)];
    p.b.col(i).segment(plant_at, n) = s_->gamma_force.col(static_cast<Eigen::Index>(l));
    p.b(plant_at + n + 1 + i, i) = 1.0;
    p.c.row(i).segment(plant_at, n) = s_->plant.ss.c.row(static_cast<Eigen::Index>(s_->plant.output_displacement(l)));
  }
  return p;
}

Complex LoopModel::notch_response(double f_hz) const {
  if (notches_.count == 0) return 1.0;
  const std::vector<filters::BiquadCoefficients> v(
      notches_.sections.begin(), notches_.sections.begin() + static_cast<std::ptrdiff_t>(notches_.count));
  return filters::digital_response(v, 1.0, f_hz, cfg_.loop.rate_hz);
}

Complex LoopModel::feedback_continuous(double f_hz, double gain, int polarity) const {
  const Complex s(0.0, kTwoPi * f_hz);
  return polarity * gain / chain_.params.actuator_constant_n_per_v * chain_.filters_analog(f_hz) *
         notch_response(f_hz) * s_->plant.actuator.n_per_v(f_hz) * s_->sensor_model.analog_response(f_hz) * s * s;
}

Complex LoopModel::loop_continuous(double f_hz, double gain, int polarity) const {
  return -feedback_continuous(f_hz, gain, polarity) * s_->plant.receptance(s_->sensor, actuator_location(), f_hz);
}

Complex LoopModel::open_continuous(std::size_t g, std::size_t h, double f_hz) const {
  return s_->plant.receptance(g, h, f_hz);
}

Complex LoopModel::closed_with_feedback(std::size_t g, std::size_t h, double f_hz, Complex q) const {
  const std::size_t a = actuator_location();
  return s_->plant.receptance(g, h, f_hz) + s_->plant.receptance(g, a, f_hz) * q *
                                                s_->plant.receptance(s_->sensor, h, f_hz) /
                                                (1.0 - q * s_->plant.receptance(s_->sensor, a, f_hz));
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
         s_->plant.actuator.n_per_v(f_hz) * s_->sensor_model.analog_response(f_hz) * s * s;
}

Complex LoopModel::closed_sampled(std::size_t g, std::size_t h, double f_hz, double gain, int polarity) const {
  return closed_with_feedback(g, h, f_hz, feedback_sampled(f_hz, gain, polarity));
}

PlantResponse LoopModel::plant_response(double f_hz) const { return s_->response(f_hz); }

namespace {
// Volts per m/s^2 of sampled acceleration that the controller commands, with the computation delay.
// p's z^-1 is e^{-j 2 pi f / fs} at the plant's loop rate, which is this loop's (LoopModel::with_controller).
Complex discrete_feedback(const PlantResponse& p, Complex filters, double gain, int polarity, double t_n_per_v,
                          Complex sensor) {
  return p.z_inverse * (polarity * gain / t_n_per_v) * filters * sensor;
}
}  // namespace

Complex LoopModel::loop_discrete(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q =
      discrete_feedback(p, filters, gain, polarity, chain_.params.actuator_constant_n_per_v, p.sensor_response);
  return -q * p.accel_per_volt[s_->sensor];
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
  const Complex q =
      discrete_feedback(p, filters, gain, polarity, chain_.params.actuator_constant_n_per_v, p.sensor_response);
  const Complex a = p.accel_per_force[g][h] + p.accel_per_volt[g] * q * p.accel_per_force[s_->sensor][h] /
                                                  (1.0 - q * p.accel_per_volt[s_->sensor]);
  const double w = kTwoPi * p.f_hz;
  return a / (-w * w);
}

Complex LoopModel::command_per_force(const PlantResponse& p, Complex filters, std::size_t h, double gain,
                                     int polarity) const {
  return command_per_force(p, feedback_discrete(p, filters, gain, polarity), h);
}

Complex LoopModel::feedback_discrete(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  return discrete_feedback(p, filters, gain, polarity, chain_.params.actuator_constant_n_per_v, p.sensor_response);
}

Complex LoopModel::command_per_force(const PlantResponse& p, Complex q, std::size_t h) const {
  return q * p.accel_per_force[s_->sensor][h] / (1.0 - q * p.accel_per_volt[s_->sensor]);
}

Complex LoopModel::command_per_sensor_noise(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q_noise = discrete_feedback(p, filters, gain, polarity, chain_.params.actuator_constant_n_per_v, 1.0);
  const Complex q = q_noise * p.sensor_response;
  return q_noise / (1.0 - q * p.accel_per_volt[s_->sensor]);
}

Complex LoopModel::command_per_open_accel(const PlantResponse& p, Complex filters, double gain, int polarity) const {
  const Complex q =
      discrete_feedback(p, filters, gain, polarity, chain_.params.actuator_constant_n_per_v, p.sensor_response);
  return q / (1.0 - q * p.accel_per_volt[s_->sensor]);
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

}  // namespace robodamp::analysis
