#include "analysis/quiet_command.hpp"

#include <cmath>

namespace robodamp::analysis {

namespace {
constexpr double kLowestHz = 0.01;  // the grid's bottom: slower swells take minutes to build
constexpr int kPoints = 4000;       // log-spaced up to Nyquist: 0.3 % steps, finer than a 1 % wide peak
}  // namespace

QuietCommand quiet_command(const LoopModel& m, double gain, int polarity) {
  const config::Config& cfg = m.config();
  const double fs = cfg.loop.rate_hz, nyquist = 0.5 * fs;
  const double lsb = m.sensor_model().lsb_mps2(), noise = m.sensor_model().noise_rms_mps2();
  const double density = (noise * noise + lsb * lsb / 12.0) / nyquist;  // (m/s^2)^2 / Hz, one-sided
  QuietCommand out;
  double power = 0.0, peak = 0.0, f_prev = 0.0, d_prev = 0.0;
  const LogGrid grid{kLowestHz, 0.999 * nyquist, kPoints - 1};
  const auto sweep = m.plant_sweep(grid);  // the plant on the grid, shared by the loops on this plant
  for (int i = 0; i < kPoints; ++i) {
    const double f = grid.at(i);
    const PlantResponse& p = (*sweep)[static_cast<std::size_t>(i)];
    const double d = std::norm(m.command_per_sensor_noise(p, m.chain_filters_digital(f), gain, polarity)) * density;
    if (i > 0) power += 0.5 * (d + d_prev) * (f - f_prev);
    if (d > peak) peak = d, out.peak_density_hz = f;
    f_prev = f, d_prev = d;
  }
  out.noise_rms_v = std::sqrt(power);
  const auto& dist = cfg.disturbances;
  if (dist.drives_on && dist.drive_vibration_mps2 > 0.0 && dist.drive_vibration_hz > 0.0 &&
      dist.drive_vibration_hz < nyquist) {
    const double f = dist.drive_vibration_hz;
    const PlantResponse p = m.plant_response(f);
    out.vibration_rms_v = std::abs(m.command_per_open_accel(p, m.chain_filters_digital(f), gain, polarity)) *
                          dist.drive_vibration_mps2 / std::sqrt(2.0);
  }
  out.rms_v = std::hypot(out.noise_rms_v, out.vibration_rms_v);
  return out;
}

}  // namespace robodamp::analysis
