// Modal identification from one FRF (docs/identification.md, "Modes"): a least-squares complex-frequency
// (LSCF) common-denominator fit gives the poles at increasing model orders (the stabilisation diagram);
// the poles that stay put across orders are the structure's; residues then follow by linear least squares
// in the frequency domain (LSFD) with lower and upper residual terms; a Levenberg-Marquardt refinement of
// all of them on the relative error removes the bias the linearised pole fit has under noise. Receptance in, Eq. 1's residue form
// out (sigma = residue_re + i residue_im with the pole -zeta wn + i wd, as the presets write it).
// Deterministic (no random starts). Off the real-time path.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "identify/numeric_csv.hpp"

namespace robodamp::identify {

using Complex = std::complex<double>;

struct FrfData {
  std::vector<double> f_hz;
  std::vector<Complex> h;         // receptance, m/N
  std::vector<double> coherence;  // empty: all 1
};

struct ModalFitSettings {
  double band_lo_hz{0.0}, band_hi_hz{0.0};  // 0, 0: the whole record
  int max_order{40};                        // highest denominator order of the diagram (even)
  double stable_freq{0.01};                 // a pole is stable when it moves less than this (relative) ...
  double stable_damping{0.05};              // ... and its damping less than this from the order below
  int stable_orders{3};                     // ... over this many consecutive orders
  double min_coherence{0.8};                // bins below it are left out of the fit
  double wide_band_ratio{40.0};             // a band with hi / lo above this is fitted in sub-bands
};

struct IdentifiedMode {
  double natural_freq_hz{0.0};
  double damping_ratio{0.0};
  double residue_re{0.0}, residue_im{0.0};  // Eq. 1 sigma, m/N (x rad/s as in the presets' residue form)
  double stiffness_n_per_m{0.0};            // wn / (2 |sigma|) (the modal stiffness of a real mode)
};

struct StabilisationPoint {
  int order{0};
  double freq_hz{0.0}, damping_ratio{0.0};
  bool stable{false};
};

struct ModalFit {
  std::vector<IdentifiedMode> modes;
  double fit_error_pct{0.0};  // RMS of |H - H_fit| over RMS of |H| in the band, %
  double band_lo_hz{0.0}, band_hi_hz{0.0};
  Complex lower_residual{0.0}, upper_residual{0.0};
  std::vector<StabilisationPoint> diagram;
  std::vector<Complex> fitted;  // at the data's frequencies in the band
  std::vector<double> fitted_f_hz;
};

// Throws std::invalid_argument: too few points, non-finite values, no coherent band, no stable pole.
[[nodiscard]] ModalFit fit_modes(const FrfData& data, const ModalFitSettings& settings);

// The fitted model (modes and residual terms) at any frequency, m/N.
[[nodiscard]] Complex fitted_receptance(const ModalFit& fit, double f_hz);

enum class FrfKind { kReceptance, kMobility, kAccelerance };
// Reads `freq_hz,re_m_per_n,im_m_per_n[,coherence]` (header required) holding an FRF of the given kind,
// and returns it as receptance (mobility / (i w), accelerance / -w^2). Throws std::invalid_argument with
// the file and line of the first problem.
[[nodiscard]] FrfData read_frf_csv(const std::string& path, FrfKind kind);

// The H1 FRF and coherence (analysis/spectral.hpp, Welch: Hann segments of segment_s with the overlap)
// from time series `time_s,force_n,response` at a constant sample rate, the response of the given kind
// (displacement m, velocity m/s or acceleration m/s^2), returned as receptance up to max_hz. Throws
// std::invalid_argument with the file and line of the first problem, or for an uneven time step.
[[nodiscard]] FrfData frf_from_time_series_csv(const std::string& path, FrfKind response_kind, double segment_s,
                                               double overlap, double max_hz);
// The same from the force and response already read (a universal file's time histories).
[[nodiscard]] FrfData frf_from_time_series(const TimeSeries& series, FrfKind response_kind, double segment_s,
                                           double overlap, double max_hz);

}  // namespace robodamp::identify
