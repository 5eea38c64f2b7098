// Listening to a recorded cut (docs/milling.md, "Listening to a recorded cut"): a vibration or sound
// signal from a real machine in; chatter over time, its frequency, and the spindle speeds to try next out.
// The verdict of each window is the cell's live chatter indicator's (milling/chatter_indicator.hpp: the
// once-per-revolution statistic and the non-harmonic energy share, its floor, persistence and trend): one
// implementation. Before it, the recording is checked (non-finite samples, clipping, a DC offset, too short,
// a rate too low for the band) and brought down to the band that matters (an anti-aliased decimation);
// a spindle speed not given is estimated from the signal's own harmonics. Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "milling/chatter_indicator.hpp"

namespace robodamp::milling {

struct RecordedSignal {
  std::string source;
  double rate_hz{0.0};
  std::vector<double> samples;
  bool acceleration_mps2{true};  // in m/s^2 (the indicator's floor applies); false: another quantity
  std::string unit;              // as the file said ("m/s^2", "Pa", "" unknown)
  // The spindle speed per sample when the recording holds it (a speed column, a robodamp recording's
  // spindle commands); empty: one speed for the whole recording.
  std::vector<double> rpm;
  std::string rpm_from;  // where it came from
};

struct ListenSettings {
  int teeth{0};                             // required
  std::optional<double> rpm;                // nullopt: estimated
  double rpm_min{100.0}, rpm_max{30000.0};  // where the estimate searches (and the speeds to try lie)
  double max_hz{1000.0};                    // the band analysed: decimated to about 2.5 x this
  double window_s{4.0};                     // one verdict per window (the indicator's span: chatter_indicator.hpp)
  std::optional<double> floor;              // non-harmonic RMS below it is not chatter, in the signal's unit
                                            // (default: the indicator's 0.05 m/s^2 for an acceleration)
  ChatterIndicatorSettings indicator;
};

enum class WindowVerdict { kStable, kChatter, kNoSignal };
[[nodiscard]] const char* to_string(WindowVerdict v);

struct ListenWindow {
  double start_s{0.0}, end_s{0.0};
  double rpm{0.0};  // the speed the window was judged at
  WindowVerdict verdict{WindowVerdict::kNoSignal};
  double chatter_hz{0.0};
  double chatter_share{0.0};   // the non-harmonic share of the displacement's energy
  double rms{0.0};             // in the signal's unit
  ChatterIndicator indicator;  // the indicator's figures
};

struct SpeedToTry {
  double rpm{0.0};
  int lobe{0};  // k: the tooth frequency is chatter_hz / k
};

struct ListenReport {
  std::vector<ListenWindow> windows;
  std::optional<double> onset_s, end_s;  // the first chatter window's start, the last one's end
  double chatter_hz{0.0};                // median over the chatter windows (0: none)
  double rpm{0.0};
  std::string rpm_source;  // "given", or how it was estimated and how sure
  double rate_hz{0.0}, analysed_rate_hz{0.0};
  std::size_t samples{0};
  std::vector<std::string> warnings;  // what is awkward about the recording, said plainly
  std::vector<SpeedToTry> speeds;     // the pockets 60 f_c / (N k) within [rpm_min, rpm_max], nearest first
  // The spectrogram of the analysed signal: one column per half window (Hann), its magnitude in dB at
  // spectrogram_hz (two bins up to max_hz, at most 400 rows evenly spaced in log frequency: the largest bin
  // of each).
  std::vector<double> spectrogram_t_s, spectrogram_hz;
  std::vector<std::vector<double>> spectrogram_db;  // [column][row]
};

// Throws std::invalid_argument with the reason: no teeth, a rate too low for the band or the spindle,
// too short for one window, no spindle speed found.
[[nodiscard]] ListenReport listen(const RecordedSignal& signal, const ListenSettings& s);

// The spindle speed from the signal's harmonics: the comb (spindle and tooth-passing lines) that carries
// most of the spectrum's peaks, its strength (share of the spectrum's energy on the comb) in how_sure.
struct RpmEstimate {
  double rpm{0.0};
  double comb_share{0.0};
  std::string how;
};
[[nodiscard]] std::optional<RpmEstimate> estimate_rpm(const std::vector<double>& x, double rate_hz, int teeth,
                                                      double rpm_min, double rpm_max);

// The stable pockets of a chatter frequency: the tooth frequency at f_c / k, k = 1, 2, ..., in range,
// nearest the current speed first.
[[nodiscard]] std::vector<SpeedToTry> pockets(double chatter_hz, int teeth, double rpm_now, double rpm_min,
                                              double rpm_max);

}  // namespace robodamp::milling
