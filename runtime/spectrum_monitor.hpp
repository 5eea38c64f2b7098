// The control accelerometer's spectrum for the operator's screen (the DDS spectrum topic, docs/dashboard.md):
// the drain thread's frames averaged down to about 1 kHz in blocks (a display, not a measurement: the block
// mean is the anti-alias filter), the last seconds kept, and Welch's average of Hann windows computed at
// most once a second of loop time. With the robot modes of the configuration (a pose-scheduled cell puts the
// modes at the robot's pose in their place: runtime::Cell::spectrum_at_pose) and the spindle's tooth passing
// frequency (from the set_spindle commands in the frames) to mark on the plot. Off the real-time path.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "analysis/fft.hpp"
#include "config/config.hpp"
#include "dds/bridge.hpp"
#include "rt/telemetry_frame.hpp"

namespace robodamp::runtime {

struct SpectrumSettings {
  double display_rate_hz{1000.0};  // the block-averaged rate (at most the loop's)
  std::size_t segment{2048};       // samples per Hann window at that rate (0.49 Hz bins at 1 kHz)
  std::size_t segments{7};         // averaged, half overlapping: 8 s at 1 kHz
  double period_s{1.0};            // loop time between spectra
};

class SpectrumMonitor {
 public:
  SpectrumMonitor(const config::Config& cfg, SpectrumSettings s = {});

  // The drain thread, every frame.
  void on_frame(const rt::TelemetryFrame& f);
  // Any thread: a new spectrum when period_s of loop time has passed since the last and the record is full.
  [[nodiscard]] std::optional<dds::SpectrumSample> next();

  [[nodiscard]] double display_rate_hz() const { return fs_hz_; }
  // The configuration's robot modes (each natural frequency once).
  [[nodiscard]] const std::vector<float>& modes_hz() const { return modes_hz_; }

 private:
  SpectrumSettings s_;
  int teeth_;
  std::size_t block_;  // loop samples per display sample
  double fs_hz_;
  std::vector<float> modes_hz_;
  std::unique_ptr<analysis::RealFft> fft_;  // the caller of next() only

  std::mutex m_;
  std::vector<double> ring_;  // display samples, circular
  std::size_t head_{0}, filled_{0};
  double block_sum_{0.0};
  std::size_t in_block_{0};
  double rpm_{0.0};
  rt::TelemetryFrame last_{};
  double published_s_{-1e9};
};

}  // namespace robodamp::runtime
