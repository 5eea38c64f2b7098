// The kernels compared by the benchmarks: the product's chain and controller, and a plain
// hand-written biquad cascade with the same sections (no NaN guard, no swap history).
#pragma once

#include <array>
#include <cmath>

#include "config/config.hpp"
#include "analysis/chain_design.hpp"
#include "control/controller.hpp"

namespace robodamp::bench {

inline analysis::ChainDesign default_design() {
  return analysis::design_chain(config::load_config_file(ROBODAMP_SOURCE_DIR "/config/presets/horizontal_c2.yaml"));
}

// The default design with 8 spindle-locked notches (3000 rpm x 3 teeth: 150 to 1200 Hz), running.
inline control::ControllerParams notched_params() {
  control::ControllerParams p = default_design().params;
  p.harmonic_notch.enabled = true;
  p.harmonic_notch.harmonics = 8;
  p.harmonic_notch.bandwidth_hz = 10.0;
  p.harmonic_notch.depth_db = 30.0;
  p.harmonic_notch.fade_s = 0.0;
  p.spindle_teeth = 3;
  return p;
}
inline constexpr double kNotchedRpm = 3000.0;

// The same sections as notched_params() running: the chain's, then the 8 notches at their centres.
inline filters::SosCoefficients notched_sections() {
  const control::ControllerParams p = notched_params();
  filters::SosCoefficients c = p.sections;
  const double tooth_hz = kNotchedRpm * p.spindle_teeth / 60.0;
  for (int k = 1; k <= 8; ++k)
    c.sections[c.count++] = filters::HarmonicNotchBank::design(k * tooth_hz, 10.0, 30.0, p.fs_hz);
  return c;
}

class PlainCascade {
 public:
  explicit PlainCascade(const filters::SosCoefficients& c) : n_(c.count) {
    for (std::size_t i = 0; i < n_; ++i) {
      const auto& k = c.sections[i];
      s_[i] = {k.b0, k.b1, k.b2, k.a1, k.a2, 0.0, 0.0};
    }
  }
  double process(double x) noexcept {
    for (std::size_t i = 0; i < n_; ++i) {
      Section& s = s_[i];
      const double y = s.b0 * x + s.z1;
      s.z1 = s.b1 * x - s.a1 * y + s.z2;
      s.z2 = s.b2 * x - s.a2 * y;
      x = y;
    }
    return x;
  }

 private:
  struct Section {
    double b0, b1, b2, a1, a2, z1, z2;
  };
  std::array<Section, filters::kMaxSections> s_{};
  std::size_t n_;
};

// Closed-loop dependency: each input depends on the last output, so samples cannot be overlapped.
inline std::array<double, 1024> excitation() {
  std::array<double, 1024> u{};
  for (std::size_t i = 0; i < u.size(); ++i)
    u[i] = std::sin(0.0116 * static_cast<double>(i)) + 0.1 * std::sin(1.7 * static_cast<double>(i));
  return u;
}

template <class Kernel>
double run_closed_loop(Kernel& k, const std::array<double, 1024>& u, long n) {
  double y = 0.0;
  for (long i = 0; i < n; ++i) y = k(u[static_cast<std::size_t>(i) & 1023U] - 0.5 * y);
  return y;
}

}  // namespace robodamp::bench
