#include "analysis/bench_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "control/controller.hpp"
#include "sim_plant/plant.hpp"
#include "units/units.hpp"

namespace robodamp::analysis {

namespace {

constexpr double kPretriggerS = 0.05;

// The control sensor's settings with the measurement accelerometers' coupling.
config::SensorConfig measurement_sensor(const config::Config& cfg) {
  config::SensorConfig s = cfg.sensor;
  s.highpass_hz = cfg.bench.measurement_highpass_hz;
  return s;
}

// Time for the controller's chain and the drive vibration's start-up to settle before recording.
double settle_time_s(const control::ControllerParams& p) { return 2.0 + p.settle_s; }

}  // namespace

MeasuredPeak measured_peak(const FrfEstimate& e, double lo, double hi) {
  std::size_t best = 0;
  double best_mag = -1.0;
  for (std::size_t k = 0; k < e.f_hz.size(); ++k)
    if (e.f_hz[k] >= lo && e.f_hz[k] <= hi && std::abs(e.h1[k]) > best_mag) best_mag = std::abs(e.h1[k]), best = k;
  MeasuredPeak p{e.f_hz[best], best_mag, 1.0};
  if (best > 0 && best + 1 < e.f_hz.size()) {
    const double a = std::abs(e.h1[best - 1]), b = best_mag, c = std::abs(e.h1[best + 1]);
    const double den = a - 2.0 * b + c;
    if (den < 0.0) {
      const double d = 0.5 * (a - c) / den;  // vertex offset in bins, |d| <= 0.5
      p.freq_hz += d * e.grid_hz;
      p.magnitude_m_per_n = b - 0.25 * (a - c) * d;
    }
  }
  for (std::size_t k = 0; k < e.f_hz.size(); ++k)
    if (std::abs(e.f_hz[k] - p.freq_hz) <= 0.1 * p.freq_hz) p.coherence_min = std::min(p.coherence_min, e.coherence[k]);
  return p;
}

Bench::Bench(const config::Config& cfg) : cfg_(cfg), model_(cfg) {}

sim::Plant Bench::make_plant() const {
  sim::Plant plant(model_.plant(), cfg_);
  if (cfg_.disturbances.drives_on) plant.add_excitation(sim::make_drive_vibration(model_.plant(), cfg_));
  return plant;
}

control::ControllerParams Bench::controller_params(double gain, int polarity) const {
  control::ControllerParams params = model_.chain().params;
  params.gain_ns_per_m = gain;
  params.polarity = polarity;
  return params;
}

ImpactCampaign::ImpactCampaign(const config::Config& cfg, sim::Plant& plant, const ImpactTest& t)
    : cfg_(cfg), plant_(plant), test_(t) {
  const double fs = cfg.loop.rate_hz;
  record_n_ = static_cast<std::size_t>(std::lround(cfg.bench.record_s * fs));
  const std::size_t nl = plant.model().locations.size();
  for (std::size_t l = 0; l < nl; ++l)
    meas_.emplace_back(measurement_sensor(cfg), fs, cfg.disturbances.seed * 7919 + 101 * (l + 1) + 13 * t.excitation);
  const auto records = static_cast<std::size_t>(cfg.bench.averages);
  force_.assign(records, std::vector<double>(record_n_));
  response_.assign(records, std::vector<std::vector<double>>(nl, std::vector<double>(record_n_)));
}

void ImpactCampaign::start(double start_s) {
  if (started()) return;
  start_s_ = start_s;
  const double fs = cfg_.loop.rate_hz;
  // Hits come at irregular intervals, as from an operator (seeded): the drive vibration then enters each
  // record with a random phase and averages out of the cross spectrum instead of adding coherently.
  std::mt19937_64 rng(cfg_.disturbances.seed * 31 + test_.excitation);
  std::uniform_real_distribution<double> gap(0.0, 1.0);
  std::vector<double> hits;
  double t = start_s;
  for (int i = 0; i < cfg_.bench.averages; ++i) {
    t += gap(rng);
    start_n_.push_back(static_cast<std::size_t>(std::lround(t * fs)));
    hits.push_back(t + kPretriggerS);
    t += cfg_.bench.record_s;
  }
  hammer_ = plant_.add_excitation(
      std::make_unique<sim::ImpactHammer>(test_.excitation, test_.peak_n, test_.duration_ms * 1e-3, hits));
  total_ = start_n_.back() + record_n_;
}

void ImpactCampaign::before_step(std::size_t k) noexcept {
  if (!started()) return;
  while (seg_ + 1 < start_n_.size() && k >= start_n_[seg_ + 1]) ++seg_;
  if (k < start_n_[seg_] || k >= start_n_[seg_] + record_n_) return;
  const std::size_t i = k - start_n_[seg_];
  for (std::size_t l = 0; l < meas_.size(); ++l) response_[seg_][l][i] = meas_[l].measure(plant_.acceleration_mps2(l));
}

void ImpactCampaign::after_step(std::size_t k) noexcept {
  if (!started() || k < start_n_[seg_] || k >= start_n_[seg_] + record_n_) return;
  const std::size_t i = k - start_n_[seg_];
  force_[seg_][i] = plant_.excitation_force_n(hammer_);
  if (i + 1 == record_n_) ++records_;
}

std::vector<FrfEstimate> ImpactCampaign::receptance() const {
  FrfAccumulator acc(record_n_, cfg_.loop.rate_hz, cfg_.bench.zero_pad, Window::kRectangular,
                     cfg_.analysis.band_max_hz * 1.5, meas_.size());
  for (int r = 0; r < records_; ++r)
    acc.add(force_[static_cast<std::size_t>(r)], response_[static_cast<std::size_t>(r)]);
  // What the records hold, per location, is not yet the structure's accelerance A = M + d + v s (modal part,
  // direct term and, where the residues' real parts do not sum to zero as in the presets' Table 1, the
  // impulse a force step causes): each accelerometer's AC coupling is in it (divided out, as modal software
  // does with a transducer's calibration), and the timing of the samples: a force sample is its tick's mean,
  // centred half a tick after its label, an acceleration sample is the left limit at its tick, whose direct
  // term takes the tick before's force, and no sample holds the impulse. So the records give
  // a = M e^{-iwT/2} + d e^{-iwT}, and A = (a - d e^{-iwT}) e^{iwT/2} + d + v iw (docs/identification.md,
  // "The impact test's FRF").
  const double tick_s = 1.0 / cfg_.loop.rate_hz;
  const sim::PlantModel& model = plant_.model();
  const auto in = static_cast<Eigen::Index>(model.input_force(test_.excitation));
  std::vector<FrfEstimate> out;
  for (std::size_t l = 0; l < meas_.size(); ++l) {
    FrfEstimate e = acc.result(l);
    const double d = model.ss.d(static_cast<Eigen::Index>(model.output_acceleration(l)), in);
    const double v = model.ss.d(static_cast<Eigen::Index>(model.output_velocity(l)), in);
    for (std::size_t k = 0; k < e.f_hz.size(); ++k) {
      const double wt = kTwoPi * e.f_hz[k] * tick_s;
      const std::complex<double> a = e.h1[k] / meas_[l].analog_response(e.f_hz[k]);
      e.h1[k] = (a - d * std::polar(1.0, -wt)) * std::polar(1.0, 0.5 * wt) + d +
                std::complex<double>(0.0, kTwoPi * e.f_hz[k] * v);
    }
    accelerance_to_receptance(e);
    out.push_back(std::move(e));
  }
  return out;
}

ImpactTestResult Bench::impact_test(const ImpactTest& t) const {
  const auto wall0 = std::chrono::steady_clock::now();
  const double fs = cfg_.loop.rate_hz;
  sim::Plant plant = make_plant();
  const control::ControllerParams params = controller_params(t.gain_ns_per_m, t.polarity);
  control::Controller controller(params);
  ImpactCampaign campaign(cfg_, plant, t);
  campaign.start(settle_time_s(params));
  ImpactTestResult r;
  double command = 0.0;
  std::uint64_t saturated_ticks = 0;
  for (std::size_t k = 0; k < campaign.end_tick(); ++k) {
    // At t_k: sample, compute; the command reaches the amplifier at the next tick.
    campaign.before_step(k);
    const sim::SensorReading s = plant.sense();
    double next = 0.0;
    if (t.control_on) {
      const auto c0 = controller.counters();
      next = controller.update(s.accel_mps2);
      const auto& c1 = controller.counters();
      if (c1.force_limited + c1.voltage_limited + c1.slew_limited >
          c0.force_limited + c0.voltage_limited + c0.slew_limited)
        ++saturated_ticks;
    }
    const auto limited0 = plant.counters().force_limited + plant.counters().voltage_clipped;
    plant.step(command);
    if (plant.counters().force_limited + plant.counters().voltage_clipped > limited0) ++saturated_ticks;
    command = next;
    r.peak_command_v = std::max(r.peak_command_v, std::abs(command));
    campaign.after_step(k);
    r.peak_actuator_force_n = std::max(r.peak_actuator_force_n, std::abs(plant.actuator_force_n()));
    if (!std::isfinite(plant.acceleration_mps2(0))) r.finite = false;
  }
  r.receptance = campaign.receptance();
  r.saturation_time_s = static_cast<double>(saturated_ticks) / fs;
  r.simulated_s = static_cast<double>(campaign.end_tick()) / fs;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

DivergenceRun Bench::divergence_run(double gain, int polarity) const {
  const double fs = cfg_.loop.rate_hz;
  DivergenceRun d;
  d.gain_ns_per_m = gain;
  const double rho = model_.spectral_radius(gain, polarity);
  d.predicted_unstable = rho >= 1.0;
  d.predicted_growth_per_s = fs * std::log(rho);
  sim::Plant plant = make_plant();
  const double t_hit = 1.0;
  plant.add_excitation(std::make_unique<sim::ImpactHammer>(model_.actuator_location(), cfg_.bench.impact_peak_n,
                                                           cfg_.bench.impact_duration_ms * 1e-3,
                                                           std::vector<double>{t_hit}));
  control::Controller controller(controller_params(gain, polarity));
  const auto n = static_cast<std::size_t>(std::lround(cfg_.bench.sweep_duration_s * fs));
  const auto win = static_cast<std::size_t>(std::lround(d.window_s * fs));
  double command = 0.0, sum2 = 0.0;
  std::uint64_t saturated = 0;
  std::vector<bool> window_saturated;
  bool sat_in_window = false;
  for (std::size_t k = 0; k < n; ++k) {
    const auto c0 = controller.counters().force_limited + controller.counters().voltage_limited;
    const double next = controller.update(plant.sense().accel_mps2);
    if (controller.counters().force_limited + controller.counters().voltage_limited > c0)
      ++saturated, sat_in_window = true;
    plant.step(command);
    command = next;
    d.peak_actuator_force_n = std::max(d.peak_actuator_force_n, std::abs(plant.actuator_force_n()));
    sum2 += command * command;
    if ((k + 1) % win == 0) {
      d.envelope_v.push_back(std::sqrt(sum2 / static_cast<double>(win)));
      window_saturated.push_back(sat_in_window);
      sum2 = 0.0;
      sat_in_window = false;
    }
  }
  d.saturation_time_s = static_cast<double>(saturated) / fs;
  // Just after the impact (the first second after it) against the end of the run.
  const auto w0 = static_cast<std::size_t>(std::ceil(t_hit / d.window_s)) + 1, w1 = w0 + 4;
  double early = 0.0;
  for (std::size_t w = w0; w < std::min(w1, d.envelope_v.size()); ++w) early = std::max(early, d.envelope_v[w]);
  d.growth_ratio = early > 0.0 ? d.envelope_v.back() / early : 0.0;
  // Least-squares slope of ln RMS from the end of the impact's first second to the end of the run, or
  // to the first window at a limit (a saturated loop no longer grows exponentially).
  std::size_t w_end = d.envelope_v.size();
  for (std::size_t w = w1; w < window_saturated.size(); ++w)
    if (window_saturated[w]) {
      w_end = w;
      break;
    }
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
  for (std::size_t w = w1; w < w_end; ++w) {
    if (!(d.envelope_v[w] > 0.0)) continue;
    const double x = (static_cast<double>(w) + 0.5) * d.window_s, y = std::log(d.envelope_v[w]);
    sx += x, sy += y, sxx += x * x, sxy += x * y, m += 1;
  }
  d.measured_growth_per_s = m > 2 ? (m * sxy - sx * sy) / (m * sxx - sx * sx) : std::nan("");
  // Grew after the impact, or still at a limit at the end (a stable loop has long decayed by then).
  d.final_window_saturated = !window_saturated.empty() && window_saturated.back();
  d.diverged = d.growth_ratio > 1.0 || !std::isfinite(d.growth_ratio) || d.final_window_saturated;
  return d;
}

}  // namespace robodamp::analysis
