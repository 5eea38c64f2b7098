#include "milling/forced_command.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "analysis/task_pool.hpp"
#include "milling/cutting.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

namespace {
constexpr int kHarmonics = 16;  // of the tooth-passing frequency: the force's spectrum falls fast beyond
constexpr std::size_t kSamplesPerPeriod = 256;

// exp(i 2 pi j / kSamplesPerPeriod): harmonic k at sample n is entry k n mod kSamplesPerPeriod.
const std::array<Complex, kSamplesPerPeriod>& unit_phasors() {
  static const auto table = [] {
    std::array<Complex, kSamplesPerPeriod> t{};
    for (std::size_t j = 0; j < kSamplesPerPeriod; ++j)
      t[j] = std::polar(1.0, robodamp::kTwoPi * static_cast<double>(j) / kSamplesPerPeriod);
    return t;
  }();
  return table;
}
}  // namespace

ForcedCommand::ForcedCommand(const Structure& damped, const config::MillingConfig& job, double rpm)
    : job_(job), rpm_(rpm) {
  limit_n_ = std::numeric_limits<double>::infinity();
  const double tooth_hz = rpm * job.tool.teeth / 60.0;
  for (const auto& p : damped.controller_parts()) {
    if (p.across) throw std::invalid_argument("ForcedCommand: a controller part across the plane is not supported");
    const analysis::LoopModel& m = *p.model;
    const config::Config& c = m.config();
    limit_n_ =
        std::min({limit_n_, c.actuator.force_limit_n, c.amplifier.voltage_limit_v * c.actuator.constant_n_per_v});
    Part part;
    part.direction = p.direction;
    part.newton_per_newton.assign(kHarmonics + 1, Complex(0.0));
    for (int k = 1; k <= kHarmonics; ++k) {
      const double f = k * tooth_hz;
      if (f >= 0.5 * m.loop_rate_hz()) break;  // the loop does not see it
      const analysis::PlantResponse r = m.plant_response(f);
      part.newton_per_newton[static_cast<std::size_t>(k)] =
          c.actuator.constant_n_per_v *
          m.command_per_force(r, m.chain_filters_digital(f), p.location, p.gain_ns_per_m, p.polarity);
    }
    parts_.push_back(std::move(part));
  }
}

double ForcedCommand::peak_force_n(double axial_mm) const {
  const CutConditions cut{job_.cut.mode, job_.cut.radial_mm, axial_mm, job_.cut.feed_per_tooth_mm};
  const ForceSpectrum f =
      force_spectrum(cutter_from(job_.tool), job_.material, cut, job_.time_domain.axial_slices, kHarmonics);
  double peak = 0.0;
  for (const Part& p : parts_) {
    std::vector<Complex> c(kHarmonics + 1, Complex(0.0));
    for (std::size_t k = 1; k <= kHarmonics; ++k) {
      // The force on the tool in the cutter's frame (x feed, y wall normal) along the part's machine direction.
      const Complex fx = f.fx[k], fy = f.fy[k];
      const Complex along =
          job_.cut.feed_axis == config::Axis::kX ? (p.direction == 0 ? fx : fy) : (p.direction == 0 ? -fy : fx);
      c[k] = p.newton_per_newton[k] * along;
    }
    const auto& unit = unit_phasors();
    for (std::size_t n = 0; n < kSamplesPerPeriod; ++n) {
      double v = 0.0;
      for (std::size_t k = 1; k <= kHarmonics; ++k) v += 2.0 * (c[k] * unit[(k * n) % kSamplesPerPeriod]).real();
      peak = std::max(peak, std::abs(v));
    }
  }
  return peak;
}

double ForcedCommand::holding_depth_mm(double max_mm) const {
  if (!(max_mm > 0.0) || !std::isfinite(max_mm)) return max_mm;
  // The first depth where the limit is crossed, scanning up: with the helix the force's harmonics cancel at some
  // depths, so the peak is not monotone and a deeper cut can hold where a shallower one does not.
  constexpr int kSteps = 64;
  double lo = 0.0, hi = max_mm;
  bool crossed = false;
  for (int i = 1; i <= kSteps && !crossed; ++i) {
    const double b = max_mm * i / kSteps;
    if (peak_force_n(b) > limit_n_)
      hi = b, crossed = true;
    else
      lo = b;
  }
  if (!crossed) return max_mm;
  while (hi - lo > 1e-4 * hi) {
    const double mid = 0.5 * (lo + hi);
    (peak_force_n(mid) <= limit_n_ ? lo : hi) = mid;
  }
  return lo;
}

std::vector<double> holding_limits_mm(const Structure& damped, const config::MillingConfig& job,
                                      const std::vector<double>& rpm, const std::vector<double>& limit_mm,
                                      std::size_t threads) {
  std::vector<double> out = limit_mm;
  if (!damped.damped() || !damped.has_controller()) return out;
  std::vector<std::function<void()>> tasks;
  for (std::size_t i = 0; i < rpm.size(); ++i)
    tasks.emplace_back([&, i] { out[i] = ForcedCommand(damped, job, rpm[i]).holding_depth_mm(limit_mm[i]); });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  return out;
}

}  // namespace robodamp::milling
