#include "plot/frf_figure.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "plot/gnuplot.hpp"

namespace robodamp::plot {

namespace {

constexpr double kPi = 3.14159265358979323846;

// One phase block: a blank line wherever the phase jumps by more than half a turn (a wrap: the line breaks).
std::string phase_block(const FrfFigureInput& in, const std::vector<std::complex<double>>& h) {
  std::ostringstream out;
  double last = NAN;
  for (std::size_t i = 0; i < in.f_hz.size(); ++i) {
    const double f = in.f_hz[i];
    if (!(f > 0.0 && f >= in.band_lo_hz && f <= in.band_hi_hz)) continue;
    const double p = wrapped_phase_deg(h[i]);
    if (std::isfinite(p) && std::isfinite(last) && std::abs(p - last) > 180.0) out << '\n';
    out << num(f) << ' ' << num(p) << '\n';
    last = p;
  }
  return out.str();
}

}  // namespace

double wrapped_phase_deg(std::complex<double> h) {
  if (!std::isfinite(h.real()) || !std::isfinite(h.imag())) return NAN;
  const double d = std::arg(h) * 180.0 / kPi;  // [-180, 180]
  return d > 90.0 ? d - 360.0 : d;             // (-270, 90]
}

FrfFigure frf_figure(const FrfFigureInput& in) {
  const std::size_t n = in.f_hz.size();
  if (in.measured.size() != n || (!in.fitted.empty() && in.fitted.size() != n) ||
      (!in.coherence.empty() && in.coherence.size() != n))
    throw std::invalid_argument("FRF figure '" + in.title +
                                "': the measured, fitted and coherence columns must be as long as "
                                "the frequencies");
  if (!(in.band_hi_hz > in.band_lo_hz))
    throw std::invalid_argument("FRF figure '" + in.title + "': the band " + num(in.band_lo_hz) + "-" +
                                num(in.band_hi_hz) + " Hz is empty");
  FrfFigure fig;
  std::ostringstream d;
  for (std::size_t i = 0; i < n; ++i) {
    const double f = in.f_hz[i];
    if (!(f > 0.0 && f >= in.band_lo_hz && f <= in.band_hi_hz)) continue;
    ++fig.rows;
    d << num(f) << ' ' << num(std::abs(in.measured[i])) << ' ' << num(in.fitted.empty() ? NAN : std::abs(in.fitted[i]))
      << ' ' << num(in.coherence.empty() ? NAN : in.coherence[i]) << '\n';
  }
  if (fig.rows == 0)
    throw std::invalid_argument("FRF figure '" + in.title + "': no frequency in the band " + num(in.band_lo_hz) + "-" +
                                num(in.band_hi_hz) + " Hz");
  const std::vector<std::complex<double>> none(n, std::complex<double>(NAN, NAN));
  fig.data =
      d.str() + "\n\n" + phase_block(in, in.measured) + "\n\n" + phase_block(in, in.fitted.empty() ? none : in.fitted);
  const bool fit = !in.fitted.empty(), coh = !in.coherence.empty();
  const std::string meas = "lc rgb '#7f8c8d' t '" + in.measured_title + "'";
  const std::string fitted = "lw 2 lc rgb '#c0392b' t '" + in.fitted_title + "'";
  std::ostringstream s;
  s << "set multiplot layout " << (coh ? 3 : 2) << ",1 title '" << in.title << "'\n"
    << "set grid\nset lmargin 12\nset logscale x\nset format x '%g'\nset xrange [" << num(in.band_lo_hz) << ":"
    << num(in.band_hi_hz) << "]\n"
    << "set logscale y\nset format y '%.0e'\nset ylabel '" << in.magnitude_label << "'\n"
    << "plot DATA index 0 u 1:2 w l " << meas << (fit ? ", DATA index 0 u 1:3 w l " + fitted : std::string()) << '\n'
    << "unset logscale y\nset format y '%g'\nset ylabel 'phase (deg)'\nset yrange [-270:90]\nset ytics 90\n"
    << (coh ? "" : "set xlabel 'frequency (Hz)'\n") << "plot DATA index 1 u 1:2 w l " << meas
    << (fit ? ", DATA index 2 u 1:2 w l " + fitted : std::string()) << '\n';
  if (coh)
    s << "set yrange [0:1.05]\nset ytics 0.25\nset key bottom right\nset ylabel 'coherence'\nset xlabel 'frequency "
         "(Hz)'\n"
      << "plot DATA index 0 u 1:4 w l lc rgb '#2471a3' t 'coherence'\n";
  s << "unset multiplot\n";
  fig.script = s.str();
  return fig;
}

}  // namespace robodamp::plot
