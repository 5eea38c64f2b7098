#include "identify/modal_fit_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "analysis/spectral.hpp"
#include "identify/numeric_csv.hpp"
#include "identify/uff_frf.hpp"
#include "measfiles/uff.hpp"
#include "plot/frf_figure.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::identify {

namespace {

// A universal file's FRF record, per force.
FrfRead read_uff_frf(const FrfSource& s, bool dof_response) {
  UffSelection sel;
  sel.record = s.record;
  if (dof_response) sel.response = parse_dof(s.response);
  if (!s.reference.empty()) sel.reference = parse_dof(s.reference);
  const measfiles::UffFile file = measfiles::read_uff(s.frf_path);
  const UffFrf frf = frf_from_uff(file, s.frf_path, sel);
  if (frf.units.per_volt)
    throw std::invalid_argument(s.frf_path + ": record " + std::to_string(frf.record) +
                                " is per volt (an actuator's FRF); identify modes reads an FRF per force");
  char b[512];
  std::snprintf(b, sizeof b, "record %d: %s / %s, %s, %zu points%s\n", frf.record,
                dof_text(frf.function->response_node, frf.function->response_direction).c_str(),
                dof_text(frf.function->reference_node, frf.function->reference_direction).c_str(),
                frf.units.shown.c_str(), frf.data.f_hz.size(),
                frf.data.coherence.empty() ? ", no coherence record" : ", with its coherence");
  return {frf.data, b};
}

}  // namespace

FrfKind frf_kind_named(const std::string& kind) {
  return kind == "mobility" ? FrfKind::kMobility : kind == "accelerance" ? FrfKind::kAccelerance : FrfKind::kReceptance;
}

FrfRead read_frf_source(const FrfSource& s) {
  const bool dof_response = s.response.find_first_of("0123456789") != std::string::npos;
  if (!dof_response && s.response != "acceleration" && s.response != "velocity" && s.response != "displacement")
    throw std::invalid_argument(
        "--response '" + s.response +
        "': allowed acceleration, velocity, displacement (--series) or NODE:DIR (a universal file's record)");
  const double transform_top_hz = s.band_hz.size() == 2 ? 1.2 * s.band_hz[1] : 1e12;
  if (!s.frf_path.empty() && looks_like_uff(s.frf_path)) return read_uff_frf(s, dof_response);
  if (!s.frf_path.empty()) {
    if (s.record || dof_response || !s.reference.empty())
      throw std::invalid_argument("--record, --response NODE:DIR and --reference choose a universal file's record; " +
                                  s.frf_path + " is a table");
    return {read_frf_csv(s.frf_path, frf_kind_named(s.kind)), ""};
  }
  if (looks_like_uff(s.series_path)) {
    UffSelection sel;
    sel.record = s.record;
    if (dof_response) sel.response = parse_dof(s.response);
    const measfiles::UffFile file = measfiles::read_uff(s.series_path);
    const UffSeries u = time_series_from_uff(file, s.series_path, sel);
    char b[256];
    std::snprintf(b, sizeof b, "records %d (force) and %d (response), %zu samples at %.6g Hz\n", u.force_record,
                  u.response_record, u.series.input.size(), u.series.fs_hz);
    return {frf_from_time_series(u.series, u.kind, s.segment_s, s.overlap, transform_top_hz), b};
  }
  if (dof_response) throw std::invalid_argument("--response with --series: acceleration, velocity or displacement");
  const auto kind = s.response == "velocity"       ? FrfKind::kMobility
                    : s.response == "acceleration" ? FrfKind::kAccelerance
                                                   : FrfKind::kReceptance;
  return {frf_from_time_series_csv(s.series_path, kind, s.segment_s, s.overlap, transform_top_hz), ""};
}

ModalFitReport modal_fit_report(const ModalFit& fit, const std::string& source) {
  ModalFitReport r;
  char b[256];
  std::snprintf(b, sizeof b, "%zu modes in %.3g-%.3g Hz, fit error %.3f %% (RMS |H - fit| / RMS |H|):\n",
                fit.modes.size(), fit.band_lo_hz, fit.band_hi_hz, fit.fit_error_pct);
  r.text = b;
  r.json = {{"fit_error_pct", fit.fit_error_pct},
            {"band_hz", {fit.band_lo_hz, fit.band_hi_hz}},
            {"modes", nlohmann::json::array()}};
  std::ostringstream yaml;
  yaml << "# robodamp identify modes " << source << ": fit error " << fit.fit_error_pct
       << " %; Eq. 1 residue form in the table's frame. Paste under a robot.frfs entry or a milling part's "
          "pair.\nmodes:\n";
  for (const auto& m : fit.modes) {
    std::snprintf(b, sizeof b, "  %9.4f Hz  zeta %.5f  sigma %+.4e %+.4ei m/N  (k %.4g N/m)\n", m.natural_freq_hz,
                  m.damping_ratio, m.residue_re, m.residue_im, m.stiffness_n_per_m);
    r.text += b;
    r.json["modes"].push_back({{"natural_freq_hz", m.natural_freq_hz},
                               {"damping_ratio", m.damping_ratio},
                               {"residue_re_m_per_n", m.residue_re},
                               {"residue_im_m_per_n", m.residue_im},
                               {"stiffness_n_per_m", m.stiffness_n_per_m}});
    yaml << "  - {natural_freq_hz: " << m.natural_freq_hz << ", damping_ratio: " << m.damping_ratio
         << ", residue_re_m_per_n: " << m.residue_re << ", residue_im_m_per_n: " << m.residue_im << "}\n";
  }
  r.yaml = yaml.str();
  return r;
}

std::string plot_modal_fit(const FrfData& d, const ModalFit& fit, const std::string& dir, const std::string& prefix) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  // The fit over the whole band it was made for (not only the sub-bands' cores), at full precision, and
  // the measurement over that band with its coherence (plot/frf_figure.hpp).
  plot::FrfFigureInput in;
  char error[32];
  std::snprintf(error, sizeof error, "%.2f", fit.fit_error_pct);
  in.title = std::string("Measured and fitted receptance (fit error ") + error + " %)";
  in.f_hz = d.f_hz, in.measured = d.h, in.coherence = d.coherence;
  in.band_lo_hz = fit.band_lo_hz, in.band_hi_hz = fit.band_hi_hz;
  for (const double f : d.f_hz)
    in.fitted.push_back(f >= fit.band_lo_hz && f <= fit.band_hi_hz ? fitted_receptance(fit, f)
                                                                   : std::complex<double>(NAN, NAN));
  const plot::FrfFigure fig = plot::frf_figure(in);
  std::ofstream(dir + "/" + prefix + "_fit.dat") << fig.data;
  if (auto e = plot::run_gnuplot(fig.script, fig.data, dir + "/" + prefix + "_fit.png"); !e.empty()) return e;
  std::ostringstream diag;
  for (const auto& p : fit.diagram) diag << plot::num(p.freq_hz) << ' ' << p.order << ' ' << (p.stable ? 1 : 0) << '\n';
  const std::string s2 =
      "set title 'Stabilisation diagram (LSCF)'\nset grid\nset xlabel 'frequency (Hz)'\nset ylabel 'model order'\n"
      "plot DATA u 1:($3 == 0 ? $2 : 1/0) w p pt 1 t 'new pole', DATA u 1:($3 == 1 ? $2 : 1/0) w p pt 7 t 'stable'\n";
  return plot::run_gnuplot(s2, diag.str(), dir + "/" + prefix + "_stabilisation.png");
}

// From a CSV of the amplifier command and the transmitted force (Welch).
ActuatorFit actuator_from_force_csv(const std::string& path, double segment_s, double overlap,
                                    const std::vector<double>& band_hz, double min_coherence) {
  const TimeSeries ts = read_time_series_csv(path, "time_s,command_v,force_n");
  const auto segment = static_cast<std::size_t>(std::lround(segment_s * ts.fs_hz));
  if (segment < 16 || segment > ts.input.size())
    throw std::invalid_argument("--segment-s = " + std::to_string(segment_s) + " s = " + std::to_string(segment) +
                                " samples: allowed 16 .. the record's " + std::to_string(ts.input.size()));
  const analysis::FrfEstimate e = analysis::welch_frf(ts.input, ts.output, ts.fs_hz, segment, overlap, 0.45 * ts.fs_hz);
  ActuatorFrf g;
  for (std::size_t k = 1; k < e.f_hz.size(); ++k)
    g.f_hz.push_back(e.f_hz[k]), g.n_per_v.push_back(e.h1[k]), g.coherence.push_back(e.coherence[k]);
  ActuatorFitSettings s;
  if (band_hz.size() == 2) s.band_lo_hz = band_hz[0], s.band_hi_hz = band_hz[1];
  s.min_coherence = min_coherence;
  return fit_actuator(g, s);
}

// Measured against fitted force per volt (magnitude and phase) in dir/<name>.
std::string plot_actuator_fit(const ActuatorFit& fit, const std::string& dir, const std::string& name) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::ostringstream data;
  for (std::size_t i = 0; i < fit.f_hz.size(); ++i)
    data << fit.f_hz[i] << ' ' << std::abs(fit.measured[i]) << ' ' << std::arg(fit.measured[i]) * 180.0 / M_PI << ' '
         << std::abs(fit.fitted[i]) << ' ' << std::arg(fit.fitted[i]) * 180.0 / M_PI << '\n';
  std::ostringstream s;
  s << "set multiplot layout 2,1 title 'Actuator force per volt: measured and Eq. 3 fitted (fit error "
    << fit.fit_error_pct << " %)'\nset grid\nset logscale x\nset ylabel '|F/V| (N/V)'\n"
    << "plot DATA u 1:2 w l t 'measured (hold as 1.5 periods)', DATA u 1:4 w l lw 2 t 'fit (exactly sampled)'\n"
    << "set xlabel 'frequency (Hz)'\nset ylabel 'phase (deg)'\nplot DATA u 1:3 w l t 'measured (hold as 1.5 periods)', "
       "DATA u 1:5 w l lw 2 t 'fit (exactly sampled)'\n"
    << "unset multiplot\n";
  return plot::run_gnuplot(s.str(), data.str(), dir + "/" + name);
}

ActuatorReport actuator_report(const ActuatorFit& fit, const std::string& mounting, double min_coherence) {
  ActuatorReport r;
  char b[512];
  std::snprintf(b, sizeof b,
                "Actuator (%s mounting): T %.4f N/V, natural frequency %.4f Hz, damping ratio %.4f, delay %.4f ms\n"
                "  fit error %.3f %% (RMS |G - fit| / RMS |G|) over %.3g-%.3g Hz, %d points with coherence >= %.2f\n",
                mounting.c_str(), fit.force_constant_n_per_v, fit.natural_freq_hz, fit.damping_ratio, fit.delay_ms,
                fit.fit_error_pct, fit.band_lo_hz, fit.band_hi_hz, fit.points, min_coherence);
  r.text = b;
  r.json = {{"mounting", mounting},
            {"force_constant_n_per_v", fit.force_constant_n_per_v},
            {"natural_freq_hz", fit.natural_freq_hz},
            {"damping_ratio", fit.damping_ratio},
            {"delay_ms", fit.delay_ms},
            {"fit_error_pct", fit.fit_error_pct},
            {"band_hz", {fit.band_lo_hz, fit.band_hi_hz}},
            {"points", fit.points}};
  return r;
}

}  // namespace robodamp::identify
