#include "analysis/impact_command.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim_plant/excitation.hpp"

namespace robodamp::analysis {

ImpactCommand::ImpactCommand(const LoopModel& plant, double peak_n, double duration_s, std::size_t samples)
    : fs_(plant.loop_rate_hz()), locations_(plant.plant().locations.size()), inverse_(samples) {
  if (samples < 1024 || (samples & (samples - 1)) != 0)
    throw std::invalid_argument("ImpactCommand: the record must be a power of two of at least 1024 samples");
  const double t = 1.0 / fs_;
  // The hammer's held force per tick, exactly as the bench's plant receives it, and its DFT.
  sim::ImpactHammer hammer(0, peak_n, duration_s, {0.0});
  RealFft forward(samples);
  for (std::size_t k = 0; k < samples; ++k) forward.input()[k] = hammer.force_n(static_cast<double>(k) * t, t);
  const std::complex<double>* f = forward.forward();
  force_.assign(f, f + forward.bins());
  responses_.reserve(forward.bins() - 1);
  for (std::size_t k = 1; k < forward.bins(); ++k)
    responses_.push_back(plant.plant_response(static_cast<double>(k) * fs_ / static_cast<double>(samples)));
}

CommandPeak ImpactCommand::peak(const LoopModel& m, double gain, int polarity) {
  CommandPeak best;
  const std::size_t n = inverse_.size();
  std::vector<Complex> q(responses_.size());  // the controller's volts per sampled m/s^2, per bin
  for (std::size_t k = 0; k < responses_.size(); ++k)
    q[k] = m.feedback_discrete(responses_[k], m.chain_filters_digital(responses_[k].f_hz), gain, polarity);
  for (std::size_t h = 0; h < locations_; ++h) {
    Complex* v = inverse_.input();
    v[0] = 0.0;
    for (std::size_t k = 0; k < responses_.size(); ++k)
      v[k + 1] = m.command_per_force(responses_[k], q[k], h) * force_[k + 1] / static_cast<double>(n);
    const double* x = inverse_.inverse();
    double peak = 0.0, slew = 0.0, tail = 0.0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double a = std::abs(x[i]);
      if (a > peak) peak = a, at = i;
      if (i > 0) slew = std::max(slew, std::abs(x[i] - x[i - 1]) * fs_);
      if (i >= n - n / 10) tail = std::max(tail, a);
    }
    if (peak > best.voltage_v || h == 0) {
      best.voltage_v = peak;
      best.location = h;
      best.time_s = static_cast<double>(at) / fs_;
      best.tail_fraction = peak > 0.0 ? tail / peak : 0.0;
    }
    best.slew_v_per_s = std::max(best.slew_v_per_s, slew);
  }
  best.coil_force_n = best.voltage_v * m.chain().params.actuator_constant_n_per_v;
  return best;
}

}  // namespace robodamp::analysis
