// Chatter detection from sampled vibration signals (simulated cuts here, measured ones later):
//   - the once-per-period statistic: the signal sampled once per tooth period (once per revolution with
//     runout) repeats in a stable cut; its differences d_i = s_{i+1} - s_i decay, and their growth per
//     period is ln of the dominant Floquet multiplier's magnitude;
//   - the share of spectral energy away from the tooth-passing (or spindle) harmonics, and the chatter
//     frequency as SDM takes it from its eigenvector: the growing Floquet mode's strongest harmonic, the
//     mode's shape over one period fitted at every phase (the spectrum's strongest alias where it cannot be);
//   - a classification: stable, Hopf (quasi-periodic), period doubling (flip: the once-per-period samples
//     alternate, chatter at an odd multiple of half the tooth frequency), or tool out of cut (chatter that
//     has grown until the edges leave the chip; its mechanism is reported beside it).
// docs/milling.md, "Chatter detection", has the thresholds. Off the real-time path.
#pragma once

#include <string>
#include <vector>

namespace robodamp::milling {

enum class CutClass { kStable, kHopf, kFlip, kOutOfCut };
[[nodiscard]] const char* to_string(CutClass c);

struct ChatterThresholds {
  double growth_per_period{0.0};  // growth of the once-per-period differences above which it chatters
  double neutral_growth{1e-3};    // margin on growth_per_period (the multiplier's magnitude is estimated)
  double persistence{0.9};        // differences keeping this share of their RMS over half the window ...
  double limit_cycle_ratio{0.1};  // ... at this share of the motion or more: a limit cycle, chatter
  double out_of_cut_share{1e-3};  // chatter with more engaged steps without a chip is "out of cut"
  double settled_ratio{1e-6};     // differences below this share of the signal are settled (stable)
  double flip_angle{0.05};        // dominant multiplier's |imag| / |mu| below this, real part < 0: flip
};

struct ChatterVerdict {
  bool stable{true};
  CutClass classification{CutClass::kStable};
  // How an unstable cut chatters, whether or not the tool also leaves the cut: kFlip when the estimated
  // dominant multiplier is real and negative (the once-per-period samples alternate), kHopf otherwise;
  // kStable for a stable cut.
  CutClass mechanism{CutClass::kStable};
  double chatter_hz{0.0};                // the growing mode's strongest harmonic (0 when stable)
  double once_per_period_ratio{0.0};     // RMS of the differences over the signal's RMS (last half)
  double nonharmonic_energy_ratio{0.0};  // 0..1, DC excluded
  double growth_per_period{0.0};         // ln(multiplier): < 0 decays, > 0 grows
  double out_of_cut_share{0.0};
};

// One chatter, many frequencies (docs/milling.md, "One chatter frequency"): a regenerative chatter is one
// Floquet mode, and its vibration holds every alias f0 + k f_p and k f_p - f0 (k = 0, 1, ...) of the
// period's frequency f_p (the tooth-passing frequency). Which alias is the chatter frequency: the mode's
// strongest harmonic by displacement (SDM's eigenvector, the detector's fitted mode, the indicator's
// spectrum by displacement). The family's base f0, in [0, f_p / 2], names the same chatter whichever
// alias a band or a sensor shows: two frequencies are the same chatter when their bases agree.
[[nodiscard]] double chatter_family_hz(double chatter_hz, double period_hz);
[[nodiscard]] bool same_chatter(double a_hz, double b_hz, double period_hz, double tol_hz);

// signals: each sampled at sample_rate_hz, analysed from `start` on, whose period is samples_per_period
// (a whole number of samples). harmonic_base_periods: how many of those periods the harmonics repeat in
// (1 without runout; the teeth with runout, so the spindle frequency counts as harmonic).
[[nodiscard]] ChatterVerdict detect_chatter(const std::vector<const std::vector<double>*>& signals, std::size_t start,
                                            int samples_per_period, int harmonic_base_periods, double sample_rate_hz,
                                            double out_of_cut_share, const ChatterThresholds& t = {});

}  // namespace robodamp::milling
