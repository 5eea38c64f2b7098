// The figure a modal-test engineer reads a frequency response from (docs/identification.md, "Plots"): the
// magnitude on logarithmic axes, the phase in degrees wrapped to (-270, 90] with its line broken at each
// wrap (no vertical stroke across the panel; a receptance's phase lies between 0 and -180 deg, so the mass
// line's -180 does not flicker to +180 as it would in (-180, 180]), and the coherence, all over the analysed band alone (below
// it an impact FRF is drift and noise that fills the panel; above it nothing was fitted), the fit beside
// the measurement. The data and the gnuplot script, for plot::run_gnuplot; a test reads the data.
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

namespace robodamp::plot {

struct FrfFigureInput {
  std::string title;
  std::string magnitude_label{"|H| (m/N)"};
  std::vector<double> f_hz;
  std::vector<std::complex<double>> measured;
  std::vector<std::complex<double>> fitted;  // beside measured (NaN where none); empty: no fit drawn
  std::vector<double> coherence;             // beside measured; empty: none measured (no panel)
  double band_lo_hz{0.0}, band_hi_hz{0.0};   // the analysed band: the x axis and the rows written
  std::string measured_title{"measured"}, fitted_title{"fitted"};
};

// The data has three blocks (gnuplot's `index`), each row "f_hz value...": 0: f, |measured|, |fitted|,
// coherence (NaN where none); 1: f, the measured phase in degrees; 2: f, the fitted phase. A blank line in
// blocks 1 and 2 where the phase wraps. Only the rows with band_lo_hz <= f <= band_hi_hz and f > 0.
struct FrfFigure {
  std::string script, data;
  std::size_t rows{0};  // in the band
};

// Throws std::invalid_argument: lengths that differ, an empty band or none of the frequencies in it.
[[nodiscard]] FrfFigure frf_figure(const FrfFigureInput& in);

// The phase in degrees in (-270, 90] (NaN stays NaN).
[[nodiscard]] double wrapped_phase_deg(std::complex<double> h);

}  // namespace robodamp::plot
