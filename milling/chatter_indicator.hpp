// The online chatter indicator (docs/harmonic_notch.md, "Chatter indicator"): from the control
// accelerometer's samples as the telemetry drain receives them, over the last few seconds,
//   - the once-per-revolution statistic: a forced, stable cut repeats every spindle revolution (or every
//     tooth period when only the tooth harmonics are forced, lines_per_revolution); the RMS of
//     x(t) - x(t - one revolution) over the RMS of the signal is near 0 then and near sqrt(2) for a
//     vibration unrelated to the spindle. Taken at every sample (linear interpolation for the fractional
//     revolution), not at one phase of the revolution: sampled at one phase, a flip chatter at half the tooth
//     frequency vanishes whenever that phase meets its zero crossings (a microphone's phase shift did);
//   - the non-harmonic energy share: of the spectral energy in [band_min_hz, 0.45 x the loop rate], the
//     share more than two bins away from every spindle harmonic (Hann window; runout makes every
//     multiple of the spindle frequency a forced line), and the strongest non-harmonic frequency; by
//     displacement (the acceleration's lines / f^2), as the tooth-passing harmonics above a robot mode's
//     chatter would otherwise outweigh it by (f / f_chatter)^2;
// Chatter is indicated when both exceed their thresholds, the non-harmonic vibration exceeds a floor
// (sensor noise alone is not chatter) and it persists across the window (its quietest eighth at
// least 0.4 of its loudest: a hammer impact's decaying ring is not chatter) or grows through it (each
// quarter louder than the one before), and it is not fading (the last quarter above 0.7 of the first:
// the marks of a cut that chattered, after a change to a stable speed). Off the real-time path:
// push() per sample on the drain thread, evaluate() at the status rate; buffers allocated at construction.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace robodamp::analysis {
class RealFft;
}

namespace robodamp::milling {

struct ChatterIndicatorSettings {
  // The analysed span (at least min_revolutions revolutions when longer); no verdict until it is full (after
  // a reset too). 4 s: the spectrum's bins are 0.25 Hz, and the two bins kept clear around each spindle
  // harmonic +/-0.5 Hz. With 2 s (+/-1 Hz) a Hopf chatter 0.6 Hz from the second spindle harmonic
  // (config/milling/active_damping_c2.yaml at 700 rpm, 1.5 mm, 1.35 x the limit, runout) kept only 5-10 %
  // of the displacement's energy off the harmonics, and 7 of 8 windows of a chattering cut read stable
  // (tests/test_chatter_listen.cpp); with 4 s, 47-51 %.
  double window_s{4.0};
  double max_window_s{8.0};  // the buffer
  int min_revolutions{12};
  double band_min_hz{5.0};
  // The forced lines: every spindle harmonic (1: a spindle with runout, each tooth cutting its own chip)
  // or every tooth-passing harmonic (the teeth: no runout). Chatter near a spindle harmonic (at 700 rpm
  // on config/milling/active_damping_c2.yaml, 23.7 Hz against the second, 23.3 Hz) hides behind the
  // first within the window's resolution.
  int lines_per_revolution{1};
  // Simulated cuts of config/milling/active_damping_c2.yaml at 700 rpm (tests/test_machining.cpp): 1.0 mm,
  // stable: 0.02 and 0.0001; 2.5 mm, chatter at 24.1 Hz: 0.33 and 0.26.
  double once_per_rev_threshold{0.2};
  double nonharmonic_threshold{0.1};
  double floor_mps2{0.05};  // non-harmonic RMS below this is not chatter
  // Quietest / loudest eighth of the window: an impact ringing on the undamped 9.2 Hz mode (decay time
  // 0.87 s), hit every 2 s (`run`'s default), leaves the eighth before the next hit 1.5 s after the last:
  // about exp(-1.5 s / 0.87 s) = 0.18.
  double persistence_threshold{0.4};
  // Last quarter / first quarter of the window at or below this: fading, not chatter. A speed change
  // that ends chatter leaves the old marks on the surface, which regenerate less each pass: at 667 rpm
  // after 700 rpm (config/milling/active_damping_c2.yaml, 1.3 mm, open loop, across processes) they kept
  // the persistence above 0.4 two seconds after the change.
  double fading_threshold{0.7};
  // Chatter that is still building up fills the window unevenly (its first quarter quiet): it counts when
  // each quarter is at least this x the one before.
  double growing_step{1.1};
  // Samples that were not fresh (stale, missed ticks, invalid) are held; above this share of the window
  // there is no verdict. A loaded 2-core machine's HIL run had 7 % stale ticks, and the held samples read
  // as chatter at 25 and 56 Hz where the emulator's cut was stable.
  double max_gap_share{0.01};
  // forced_lines_snr at or above this: the spindle's lines are there (the tool is cutting).
  double forced_lines_threshold{10.0};
};

struct ChatterIndicator {
  bool valid{false};  // enough samples at a turning spindle
  double once_per_rev_ratio{0.0};
  double nonharmonic_share{0.0};  // 0..1, of the displacement's energy
  double nonharmonic_rms_mps2{0.0};
  double chatter_hz{0.0};  // strongest non-harmonic line (0 when none)
  double rms_mps2{0.0};
  // The forced lines over the noise: the mean energy per bin on the spindle harmonics (the two bins either
  // side of each) over the median per bin elsewhere (the noise floor; a chatter peak barely moves a median).
  // About 1 without a cut (an air cut, the spindle turning free); a cut's tooth-passing lines are far above.
  double forced_lines_snr{0.0};
  bool forced_lines{false};  // forced_lines_snr >= forced_lines_threshold
  double persistence{0.0};   // x(t) - x(t - 1 rev): RMS of the quietest eighth / the loudest
  double trend{0.0};         // the same, the last quarter / the first
  bool growing{false};       // each quarter louder than the one before (growing_step)
  double gap_share{0.0};     // held (not fresh) samples in the window
  bool chatter{false};
};

}  // namespace robodamp::milling

namespace robodamp::config {
struct MillingConfig;
}

namespace robodamp::milling {

// The job's forced lines per revolution: its teeth without runout (time_domain.runout_um all zero), else 1.
[[nodiscard]] int forced_lines_per_revolution(const config::MillingConfig& job);

// The top of the band the indicator hears: 0.45 x the sample rate (below the anti-alias filter's edge).
[[nodiscard]] constexpr double indicator_band_max_hz(double sample_rate_hz) { return 0.45 * sample_rate_hz; }
// The modal frequencies of the job's structure (structure_name, or the job's own when empty; every part and
// direction; modal terms only, not a damping configuration's or a robot model's) above that band,
// ascending, each once: a chatter on one of them is not heard by an indicator at this rate (a spindle or
// tool mode's chatter at kHz, on a 5 kHz loop).
[[nodiscard]] std::vector<double> modes_above_band(const config::MillingConfig& job, const std::string& structure_name,
                                                   double sample_rate_hz);

class ChatterMonitor {
 public:
  ChatterMonitor(double sample_rate_hz, ChatterIndicatorSettings s = {});
  ~ChatterMonitor();
  ChatterMonitor(const ChatterMonitor&) = delete;
  ChatterMonitor& operator=(const ChatterMonitor&) = delete;

  // One loop tick's sample; fresh false (stale, or a missed tick's place) or not finite: the last value
  // is held there and the tick counts as a gap.
  void push(double accel_mps2, bool fresh = true);
  // Forget the samples (the spindle speed changed: the window restarts).
  void reset() { count_ = 0; }
  [[nodiscard]] ChatterIndicator evaluate(double spindle_rpm);
  [[nodiscard]] const ChatterIndicatorSettings& settings() const { return s_; }

 private:
  // evaluate's steps: the window (false: no verdict from it), the measures in time, the spectrum's.
  bool fill_window(double f_sp, ChatterIndicator& out);
  void time_measures(double f_sp, ChatterIndicator& out) const;
  void spectrum_measures(double f_sp, ChatterIndicator& out);
  double fs_;
  ChatterIndicatorSettings s_;
  std::vector<double> ring_;
  std::vector<std::uint8_t> gap_;
  std::size_t head_{0}, count_{0};
  std::vector<double> window_;    // the analysed span, oldest first
  std::vector<double> off_bins_;  // the energies of the bins off the harmonics (their median)
  std::unique_ptr<analysis::RealFft> fft_;
  std::size_t fft_n_{0};
};

}  // namespace robodamp::milling
