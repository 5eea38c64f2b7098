#include "commission/report.hpp"

#include "commission/stage_detail.hpp"

#include <openssl/evp.h>

#include <cmath>
#include <cstdlib>
#include <ctime>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "plot/frf_figure.hpp"
#include "plot/gnuplot.hpp"
#include "rt/version.hpp"
#include "tune/speed_schedule_report.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;
using plot::num;

using detail::esc;
using detail::fmt;

double deg(std::complex<double> z) { return std::arg(z) * 180.0 / M_PI; }

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string sha256_hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &n, EVP_sha256(), nullptr) != 1) return "(not computed)";
  std::string hex;
  for (unsigned int i = 0; i < n; ++i) hex += fmt("%02x", static_cast<unsigned>(digest[i]));
  return hex;
}

// One plot: its PNG and its data file in dir, returned as an <img> (or the reason in the page).
class Plots {
 public:
  explicit Plots(fs::path dir) : dir_(std::move(dir)) { fs::create_directories(dir_); }
  std::string img(const std::string& name, const std::string& script, const std::string& data, const std::string& alt) {
    const fs::path png = dir_ / (name + ".png");
    std::ofstream(dir_ / (name + ".dat")) << data;
    if (const std::string e = plot::run_gnuplot(script, data, png.string()); !e.empty())
      return "<p class=bad>plot " + esc(name) + ": " + esc(e) + "</p>";
    return "<figure><img src=\"" + plot::png_data_uri(png.string()) + "\" alt=\"" + esc(alt) + "\"><figcaption>" +
           esc(alt) + "</figcaption></figure>\n";
  }

 private:
  fs::path dir_;
};

std::string identified_section(const identify::CommissioningResult& id, Plots& p) {
  std::ostringstream h;
  h << "<h2>2. Identified structure and actuator</h2>\n<table><tr><th>FRF</th><th>mode</th><th>natural frequency "
       "(Hz)</th>"
       "<th>damping ratio</th><th>residue (m/N)</th><th>fit error (%)</th></tr>\n";
  for (const auto& f : id.frfs)
    for (std::size_t k = 0; k < f.fit.modes.size(); ++k) {
      const auto& m = f.fit.modes[k];
      h << "<tr><td>" << esc(f.name) << "</td><td>" << k + 1 << "</td><td>" << fmt("%.4f", m.natural_freq_hz)
        << "</td><td>" << fmt("%.4f", m.damping_ratio) << "</td><td>" << fmt("%+.4g %+.4gi", m.residue_re, m.residue_im)
        << "</td><td>" << (k == 0 ? fmt("%.2f", f.fit.fit_error_pct) : "") << "</td></tr>\n";
    }
  h << "</table>\n";
  const auto& a = id.actuator;
  h << "<p>Actuator (Eq. 3): T " << fmt("%.4f", a.force_constant_n_per_v) << " N/V, natural frequency "
    << fmt("%.4f", a.natural_freq_hz) << " Hz, damping ratio " << fmt("%.4f", a.damping_ratio) << ", delay "
    << fmt("%.4f", a.delay_ms) << " ms; fit error " << fmt("%.2f", a.fit_error_pct) << " % over "
    << fmt("%.3g-%.3g", a.band_lo_hz, a.band_hi_hz) << " Hz (" << a.points << " points, " << id.actuator_periods
    << " chirp periods averaged).</p>\n";
  for (const auto& f : id.frfs) {
    plot::FrfFigureInput in;  // over the fitted band, with the coherence (plot/frf_figure.hpp)
    in.title =
        f.name + ": measured receptance and the fitted modes (fit error " + fmt("%.2f", f.fit.fit_error_pct) + " %)";
    in.f_hz = f.data.f_hz, in.measured = f.data.h, in.coherence = f.data.coherence;
    in.band_lo_hz = f.fit.band_lo_hz, in.band_hi_hz = f.fit.band_hi_hz;
    for (const double fh : f.data.f_hz)
      in.fitted.push_back(fh >= f.fit.band_lo_hz && fh <= f.fit.band_hi_hz ? identify::fitted_receptance(f.fit, fh)
                                                                           : std::complex<double>(NAN, NAN));
    const plot::FrfFigure fig = plot::frf_figure(in);
    h << p.img(f.name + "_fit", fig.script, fig.data,
               f.name + ": measured and fitted receptance, magnitude, phase and coherence");
    std::ostringstream g;
    for (const auto& q : f.fit.diagram) g << num(q.freq_hz) << ' ' << q.order << ' ' << (q.stable ? 1 : 0) << '\n';
    const std::string s2 =
        "set title '" + f.name +
        ": stabilisation diagram (LSCF)'\nset grid\nset xlabel 'frequency (Hz)'\n"
        "set ylabel 'model order'\nplot DATA u 1:($3 == 0 ? $2 : 1/0) w p pt 1 lc rgb '#7f8c8d' t 'new pole', "
        "DATA u 1:($3 == 1 ? $2 : 1/0) w p pt 7 lc rgb '#2471a3' t 'stable pole'\n";
    h << p.img(f.name + "_stabilisation", s2, g.str(), f.name + ": stabilisation diagram");
  }
  std::ostringstream d;
  for (std::size_t i = 0; i < a.f_hz.size(); ++i)
    d << num(a.f_hz[i]) << ' ' << num(std::abs(a.measured[i])) << ' ' << num(deg(a.measured[i])) << ' '
      << num(std::abs(a.fitted[i])) << ' ' << num(deg(a.fitted[i])) << '\n';
  const std::string s =
      "set multiplot layout 2,1 title 'Actuator force per volt: measured through the structure, and Eq. 3 fitted'\n"
      "set grid\nset logscale x\nset ylabel '|F/V| (N/V)'\nplot DATA u 1:2 w l lc rgb '#7f8c8d' t 'measured', "
      "DATA u 1:4 w l lw 2 lc rgb '#c0392b' t 'Eq. 3 fitted, through the sampled loop'\nset xlabel 'frequency "
      "(Hz)'\nset ylabel 'phase (deg)'\n"
      "plot DATA u 1:3 w l lc rgb '#7f8c8d' t 'measured', DATA u 1:5 w l lw 2 lc rgb '#c0392b' t 'Eq. 3 fitted, "
      "through the sampled loop'\n"
      "unset multiplot\n";
  h << p.img("actuator_fit", s, d.str(), "Actuator: measured and fitted force per volt");
  return h.str();
}

std::string tuned_section(const CommissionResult& r) {
  std::ostringstream h;
  h << "<h2>3. Tuned controller</h2>\n<p>Robust over the identified plant and its modes shifted by &plusmn;"
    << fmt("%.2f", r.shift_pct) << " % (" << esc(r.shift_reason) << ").</p>\n";
  if (r.robustness) {
    const tune::Robustness& rb = *r.robustness;
    const bool weak = rb.pct() < tune::kRobustShiftWarnPct;
    h << "<p" << (weak ? " class=\"warn\"><b>WARNING:</b> " : ">")
      << "Measured on the identified plant: the tuned loop stays "
      << "stable and damps the modes it damps from " << fmt("%.1f", -rb.down.pct) << " % to +" << fmt("%.1f", rb.up.pct)
      << " % of mode shift (steps of 0.5 %, at most 20 %)";
    for (const auto* l : {&rb.down, &rb.up})
      if (!l->reason.empty()) h << "; " << esc(l->reason);
    h << "." << (weak ? " A pose or tool change may move the modes further than that." : "") << "</p>\n";
  }
  if (!r.tuned) return h.str() + "<p>Not reached.</p>\n";
  const auto& e = *r.tuned;
  const auto& c = e.candidate;
  h << "<table><tr><th></th><th>identified plant</th><th>worst over the shifted plants</th></tr>\n";
  const auto row = [&](const char* name, double a, double b, const char* f) {
    h << "<tr><td>" << name << "</td><td>" << fmt(f, a) << "</td><td>" << fmt(f, b) << "</td></tr>\n";
  };
  const tune::Evaluation& n = r.tuned_nominal ? *r.tuned_nominal : e;
  row("gain K (N s/m)", n.candidate.gain_ns_per_m, c.gain_ns_per_m, "%.0f");
  row("gain margin (dB)", n.gain_margin_db, e.gain_margin_db, "%.2f");
  row("phase margin (deg)", n.phase_margin_deg, e.phase_margin_deg, "%.1f");
  row("delay margin (ms)", n.delay_margin_ms, e.delay_margin_ms, "%.2f");
  row("largest feedback phase at a mode (deg, &lt; 90 damps)", n.worst_mode_phase_deg, e.worst_mode_phase_deg, "%.1f");
  row("peak command at the bench impact (V)", n.peak_command_v, e.peak_command_v, "%.3f");
  row("command on a quiet cell (V RMS; sensor noise, ADC, drive vibration)", n.quiet_command_rms_v,
      e.quiet_command_rms_v, "%.4f");
  h << "</table>\n<p>Compensator (rational, unity gain at the match frequency): zero pair " << fmt("%.3f", c.fz_hz)
    << " Hz, &zeta; " << fmt("%.3f", c.zeta_z) << "; pole pair " << fmt("%.3f", c.fp_hz) << " Hz, &zeta; "
    << fmt("%.3f", c.zeta_p) << "; lead/lag zero " << fmt("%.3f", c.fa_hz) << " Hz, pole " << fmt("%.3f", c.fb_hz)
    << " Hz; polarity " << fmt("%+d", c.polarity) << ". Feasible: " << (e.feasible() ? "yes" : "no, " + esc(e.binding))
    << ".</p>\n";
  return h.str();
}

// The smallest and largest depth the lobes plot shows (open and damped curves, the checks), with a margin.
std::pair<double, double> depth_range(const CommissionResult& r, const tune::Verification& v) {
  double lo = INFINITY, hi = 0.0;
  auto see = [&](double mm) {
    if (std::isfinite(mm) && mm > 0.0) lo = std::min(lo, mm), hi = std::max(hi, mm);
  };
  for (const auto& c : r.open_curve_mm) see(c.second);
  for (const auto& c : v.damped_curve_mm) see(c.second);
  for (const double mm : {v.min_depth_mm, v.depth_at_speed_mm, v.time_domain_at_min_mm, v.time_domain_at_speed_mm})
    see(mm);
  if (r.cell) {
    see(r.cell->time_domain_at_min_mm), see(r.cell->time_domain_at_speed_mm);
    for (const auto& t : r.cell->cut_trials) see(t.depth_mm);
  }
  if (!(hi > 0.0)) return {0.01, 10.0};
  return {0.8 * lo, 1.25 * hi};
}

// long: one HTML section, the verification table row by row
std::string tap_test_table(const identify::TapTestConsistency& t) {
  std::ostringstream h;
  h << "<h3>The tap tests against the actuator's chirp</h3>\n<table><tr><th>mode tapped (Hz)</th><th>in the chirp "
       "(Hz)</th>"
       "<th>apart (%)</th><th>allowed (%)</th></tr>\n";
  for (const auto& m : t.modes)
    h << "<tr><td>" << fmt("%.3f", m.tap_hz) << "</td><td>" << (m.chirp_hz ? fmt("%.3f", *m.chirp_hz) : "none")
      << "</td><td class=" << (m.ok ? "ok" : "bad") << ">" << fmt("%.2f", m.difference_pct) << "</td><td>"
      << fmt("%.1f", t.tolerance_pct) << "</td></tr>\n";
  h << "</table>\n<p>" << esc(t.chirp_fit)
    << fmt(". Through the tapped structure the chirp implies an actuator that Eq. 3 "
           "fits to %.2f %% RMS (allowed %.0f %%).",
           t.chirp_residual_pct, t.residual_limit_pct);
  for (const auto& r : t.reciprocity)
    h << " " << esc(r.pair)
      << fmt(" reciprocal within %.1f %% (allowed %.0f %%).", r.difference_pct, t.reciprocity_limit_pct);
  return h.str() + "</p>\n";
}

// A real cell: what ran on the machine (the actuator's chirp, control off and on), the improvement at the
// actuator and the loop gain measured beside the analysis, with their plots.
std::string real_cell_section(const CommissionResult& r, Plots& p) {
  const RealCellCheck& c = *r.real_check;
  std::ostringstream h;
  h << "<h3>Verification on a real cell</h3>\n<p>On " << esc(c.cell)
    << ". Ran on the machine: the actuator's chirp with "
       "control off (the measure stage) and with the tuned controller ("
    << fmt("%.1f", c.wall_s)
    << " s). Not run: a hammer "
       "test (the tool tip's FRFs are the user's tap tests) and a cut; the depths above are the identified model's "
       "promise. "
       "Cut a test part with <code>robodamp chatter</code> listening to check them.</p>\n";
  if (r.tap_check) h << tap_test_table(*r.tap_check);
  h << "<table><tr><th>mode at the actuator (Hz)</th><th>measured improvement (%)</th><th>predicted "
       "(%)</th><th>difference "
       "(points)</th></tr>\n";
  for (const auto& m : c.modes) {
    const double d = m.measured_improvement_pct - m.predicted_improvement_pct;
    h << "<tr><td>" << fmt("%.2f", m.freq_hz) << "</td><td>" << fmt("%.1f", m.measured_improvement_pct) << "</td><td>"
      << fmt("%.1f", m.predicted_improvement_pct)
      << "</td><td class=" << (std::abs(d) <= c.improvement_tolerance_points ? "ok" : "bad") << ">" << fmt("%+.1f", d)
      << "</td></tr>\n";
  }
  const LoopGainCheck& g = c.loop_gain;
  auto m = [](const std::optional<double>& v, const char* u) {
    return v ? fmt("%.1f %s", *v, u) : std::string("no crossover");
  };
  h << "</table>\n<p>The loop gain by injection (L = -(c/e)/(u/e), the chirp e at the plant's input): "
    << g.compared_points
    << fmt(" lines compared where 0.1 &le; |L| &le; 10; the largest differences %.2f dB at %.1f Hz and %.1f deg at "
           "%.1f Hz "
           "(allowed %.0f dB, %.0f deg). ",
           g.max_error_db, g.error_db_at_hz, g.max_error_deg, g.error_deg_at_hz, g.tolerance_db, g.tolerance_deg)
    << "Over the chirp's band: measured GM " << m(g.measured_gm_db, "dB") << ", PM " << m(g.measured_pm_deg, "deg")
    << "; the analysis GM " << m(g.predicted_gm_db, "dB") << ", PM " << m(g.predicted_pm_deg, "deg") << ".</p>\n";
  std::ostringstream d, l;
  for (std::size_t i = 0; i < c.f_hz.size(); ++i)
    d << num(c.f_hz[i]) << ' ' << num(c.measured_open[i]) << ' ' << num(c.measured_closed[i]) << ' '
      << num(c.predicted_open[i]) << ' ' << num(c.predicted_closed[i]) << '\n';
  for (std::size_t i = 0; i < g.f_hz.size(); ++i)
    l << num(g.f_hz[i]) << ' ' << num(std::abs(g.measured[i])) << ' ' << num(std::abs(g.predicted[i])) << ' '
      << num(deg(g.measured[i])) << ' ' << num(deg(g.predicted[i])) << '\n';
  h << p.img("actuator_chirp",
             "set title 'At the actuator: acceleration per volt of chirp, control off and on, measured and "
             "predicted'\nset grid\nset logscale y\nset xlabel 'frequency (Hz)'\nset ylabel '|y/e| (m/s^2 per V)'\n"
             "plot DATA u 1:2 w l lc rgb '#95a5a6' t 'off, measured', DATA u 1:4 w l dt 2 lw 2 lc rgb '#34495e' "
             "t 'off, predicted', DATA u 1:3 w l lc rgb '#e59866' t 'on, measured', DATA u 1:5 w l dt 2 lw 2 lc "
             "rgb '#c0392b' t 'on, predicted'\n",
             d.str(), "The actuator's chirp on the cell, control off and on, beside the tuned model");
  h << p.img("loop_gain",
             "set multiplot layout 2,1 title 'The loop gain L measured on the cell (injection) and the analysis'\n"
             "set grid\nset logscale y\nset format y '%g'\nset ylabel '|L|'\nplot DATA u 1:2 w l lw 2 lc rgb '#e67e22' "
             "t 'measured', "
             "DATA u 1:3 w l dt 2 lw 2 lc rgb '#2c3e50' t 'analysis', 1 w l lc rgb '#c0392b' t '|L| = 1'\n"
             "unset logscale y\nset ylabel 'arg L (deg)'\nset xlabel 'frequency (Hz)'\nset yrange [-180:180]\n"
             "plot DATA u 1:4 w l lw 2 lc rgb '#e67e22' t 'measured', DATA u 1:5 w l dt 2 lw 2 lc rgb '#2c3e50' "
             "t 'analysis'\nunset multiplot\n",
             l.str(), "The loop gain, measured by injection on the cell and predicted by the analysis");
  return h.str();
}

// The impact tests on the cell with control off and on, beside the tuned model.
std::string impact_check_section(const CellCheck& c, const tune::Verification& v, Plots& p) {
  std::ostringstream h;
  h << "<p>The cell: " << esc(c.cell) << ". " << esc(c.cut_summary(v)) << ".</p>\n";
  h << "<h3>Impact tests on the cell, control off and on</h3>\n<table><tr><th>FRF</th><th>open peak (m/N at Hz)</th>"
       "<th>closed peak (m/N at Hz)</th><th>measured improvement (%)</th><th>predicted (%)</th><th>difference "
       "(points)</th>"
       "<th>coherence min</th></tr>\n";
  for (const auto& f : c.frfs) {
    const double diff = f.measured_improvement_pct - f.predicted_improvement_pct;
    h << "<tr><td>" << esc(f.name) << "</td><td>" << fmt("%.4g at %.2f", f.open_peak_m_per_n, f.open_peak_hz)
      << "</td><td>" << fmt("%.4g at %.2f", f.closed_peak_m_per_n, f.closed_peak_hz) << "</td><td>"
      << fmt("%.1f", f.measured_improvement_pct) << "</td><td>" << fmt("%.1f", f.predicted_improvement_pct)
      << "</td><td class=" << (std::abs(diff) <= c.improvement_tolerance_points ? "ok" : "bad") << ">"
      << fmt("%+.1f", diff) << "</td><td>" << fmt("%.3f", f.coherence_min) << "</td></tr>\n";
  }
  h << "</table>\n<p>The loop was active over " << fmt("%.1f", 100.0 * c.closed_active_share)
    << " % of the impact tests with the tuned controller; trips: " << esc(c.open_trip) << " (off), "
    << esc(c.closed_trip) << " (on); " << c.closed_saturated_ticks << " saturated ticks; " << fmt("%.1f", c.wall_s)
    << " s.</p>\n";
  for (const auto& f : c.frfs) {
    std::ostringstream d;
    for (std::size_t i = 0; i < f.f_hz.size(); ++i)
      d << num(f.f_hz[i]) << ' ' << num(f.measured_open[i]) << ' ' << num(f.measured_closed[i]) << ' '
        << num(f.predicted_open[i]) << ' ' << num(f.predicted_closed[i]) << '\n';
    const std::string s =
        "set title '" + f.name +
        ": receptance on the cell, control off and on, measured (impacts) and "
        "predicted (identified model, discrete loop)'\nset grid\nset logscale y\nset format y '%.0e'\n"
        "set xlabel 'frequency (Hz)'\nset ylabel '|H| (m/N)'\nset key top right\n"
        "plot DATA u 1:2 w l lc rgb '#95a5a6' t 'open, measured', DATA u 1:4 w l dt 2 lw 2 lc rgb '#34495e' "
        "t 'open, predicted', DATA u 1:3 w l lc rgb '#e59866' t 'closed, measured', DATA u 1:5 w l dt 2 lw 2 "
        "lc rgb '#c0392b' t 'closed, predicted'\n";
    h << p.img(f.name + "_cell", s, d.str(), f.name + ": open and closed loop on the cell, measured and predicted");
  }
  return h.str();
}

std::string verify_section(const CommissionResult& r, Plots& p) {
  std::ostringstream h;
  h << "<h2>4. Verification</h2>\n";
  if (!r.promise) return h.str() + "<p>Not reached.</p>\n";
  const auto& v = *r.promise;
  const bool hil = r.cell && !r.cell->cut_trials.empty();
  h << "<table><tr><th></th><th>speed (rpm)</th><th>promised (" << esc(v.method)
    << ", identified model) (mm)</th><th>time-domain cut, identified model (mm)</th><th>"
    << (hil           ? "the regenerative cut in the HIL emulator at the promise less 5 % (mm)"
        : r.real_cell ? "on the cell (a real cell: robodamp cuts nothing)"
                      : "time-domain cut on the cell, critical (mm)")
    << "</th></tr>\n";
  auto on_cell = [&](std::size_t i, double mm) {
    if (!r.cell) return std::string(r.real_cell ? "not cut" : "-");
    if (!hil) return fmt("%.3f", mm);
    const CutTrial& t = r.cell->cut_trials.at(i);
    return fmt("%.3f at %.1f rpm: ", t.depth_mm, t.rpm) + (t.held() ? std::string("stable") : esc(t.classification));
  };
  const auto cell_min = on_cell(0, r.cell ? r.cell->time_domain_at_min_mm : 0.0);
  const auto cell_at = on_cell(1, r.cell ? r.cell->time_domain_at_speed_mm : 0.0);
  h << "<tr><td>damped lobes' minimum</td><td>" << fmt("%.1f", v.min_rpm) << "</td><td>" << fmt("%.3f", v.min_depth_mm)
    << "</td><td>" << fmt("%.3f", v.time_domain_at_min_mm) << "</td><td>" << cell_min << "</td></tr>\n";
  h << "<tr><td>the job's speed</td><td>" << fmt("%.1f", v.speed_rpm) << "</td><td>" << fmt("%.3f", v.depth_at_speed_mm)
    << "</td><td>" << fmt("%.3f", v.time_domain_at_speed_mm) << "</td><td>" << cell_at << "</td></tr>\n";
  h << "<tr><td>open loop's minimum (SDM)</td><td></td><td>" << fmt("%.3f", v.open_min_depth_mm)
    << "</td><td></td><td></td></tr></table>\n";
  {
    std::ostringstream d;
    for (const auto& [rpm, mm] : r.open_curve_mm) d << num(rpm) << ' ' << num(mm) << '\n';
    d << "\n\n";
    for (const auto& [rpm, mm] : v.damped_curve_mm) d << num(rpm) << ' ' << num(mm) << '\n';
    d << "\n\n"
      << num(v.min_rpm) << ' ' << num(v.time_domain_at_min_mm) << '\n'
      << num(v.speed_rpm) << ' ' << num(v.time_domain_at_speed_mm) << "\n\n\n";
    if (hil)
      for (const CutTrial& t : r.cell->cut_trials) d << num(t.rpm) << ' ' << num(t.depth_mm) << '\n';
    else if (r.cell)
      d << num(v.min_rpm) << ' ' << num(r.cell->time_domain_at_min_mm) << '\n'
        << num(v.speed_rpm) << ' ' << num(r.cell->time_domain_at_speed_mm) << '\n';
    else
      d << "NaN NaN\n";
    // Every plotted depth in range: the lobes' peaks are tens of times their floor, so on a log scale.
    const auto [ymin, ymax] = depth_range(r, v);
    const std::string s =
        "set title 'Stability lobes of the job: open loop (SDM) and damped (" + v.method +
        "), identified model; the damped cut in time'\nset grid\nset xlabel 'spindle speed (rpm)'\n"
        "set ylabel 'limiting axial depth (mm), log scale'\nset key top left opaque box\nset logscale y\n"
        "set yrange [" +
        num(ymin) + ":" + num(ymax) +
        "]\n"
        "plot DATA index 0 u 1:2 w l lw 2 lc rgb '#7f8c8d' t 'open loop (SDM)', "
        "DATA index 1 u 1:2 w l lw 2 lc rgb '#2471a3' t 'damped, promised (" +
        v.method +
        ")', "
        "DATA index 2 u 1:2 w p pt 6 ps 2 lc rgb '#27ae60' t 'time-domain cut, identified model', "
        "DATA index 3 u 1:2 w p pt 7 ps 1.5 lc rgb '#c0392b' t '" +
        (hil ? std::string(r.cell->depth_ok(v)
                               ? "regenerative cut in the HIL emulator: stable at the promise - 5 %"
                               : "regenerative cut in the HIL emulator at the promise - 5 % (chatter at one)")
             : std::string("time-domain cut on the cell, critical")) +
        "'\n";
    h << p.img("lobes", s, d.str(), "Stability lobes, open and damped, with the time-domain checks");
  }
  if (r.real_check) h << real_cell_section(r, p);
  if (r.cell) h << impact_check_section(*r.cell, v, p);
  return h.str();
}

// What the damper does for the job, first, in the machinist's terms, with the one picture that says it.
std::string cut_section(const CommissionResult& r, Plots& p) {
  if (!r.schedule) return {};
  const tune::SpeedSchedule& s = *r.schedule;
  const tune::ScheduleSummary& m = s.summary;
  std::ostringstream h;
  h << "<h2>What the damper does for this job</h2>\n<p>By the accurate method (" << esc(s.method) << ") at " << m.speeds
    << " speeds over the job's range, on the identified model. ";
  if (m.job_rpm > 0.0)
    h << fmt(
        "At the job's %.1f rpm the open loop allows %.3f mm; the tuned controller at its fixed K allows %.3f mm (%+.1f "
        "%%); "
        "the speed schedule written allows <b>%.3f mm (%+.1f %%)</b>. ",
        m.job_rpm, m.job_open_mm, m.job_fixed_mm, 100.0 * (m.job_fixed_mm / m.job_open_mm - 1.0), m.job_scheduled_mm,
        100.0 * (m.job_scheduled_mm / m.job_open_mm - 1.0));
  h << fmt(
      "Over the range the schedule's minimum is <b>%.3f mm</b> (open loop %.3f mm, the tuned controller alone %.3f "
      "mm), "
      "its mean <b>x%.3f</b> the open loop's (alone x%.3f). ",
      m.scheduled_min_mm, m.open_min_mm, m.fixed_min_mm, m.scheduled_mean_ratio, m.fixed_mean_ratio);
  if (m.fixed_worse_share > 0.0)
    h << fmt(
        "<span class=bad>The tuned controller alone would be worse than no damper at %.0f %% of the speeds (down to "
        "x%.2f at "
        "%.0f rpm)</span>; ",
        100.0 * m.fixed_worse_share, m.fixed_worst_ratio, m.fixed_worst_rpm);
  h << (m.scheduled_worse_share > 0.0
            ? fmt("<span class=bad>the schedule is worse than no damper at %.1f %% of them</span>.",
                  100.0 * m.scheduled_worse_share)
            : fmt("<span class=ok>the schedule is never worse than no damper</span> (by %.1f %%) at the speeds "
                  "checked: "
                  "it runs K = 0 where no controller beats the open loop.",
                  s.settings.worse_tolerance_pct))
    << fmt(" %zu bands; every damped limit is capped where the actuator holds the cut's forced vibration (%zu of %zu "
           "were), "
           "and each the bands run is checked by a cut in time at 0.95 x it (%zu of %zu chattered; another candidate "
           "runs "
           "there, or the same at its limit in time; bands with a depth limit: %zu).</p>\n",
           s.bands.size(), s.capped_limits, s.damped_limits, s.lowered_in_time, s.limits_in_time, s.limited_bands());
  const auto [data, script] =
      tune::schedule_plot(s, "What the damper does for the job: limiting depth by spindle speed");
  h << p.img("schedule_lobes", script, data,
             "open loop (SDM), the tuned controller at its fixed K and the speed schedule "
             "(sampled-loop SDM), identified model");
  return h.str();
}

// Date (UTC), software version and commit, who, and the SHA-256 of the cell's configuration file.
std::string provenance(const CommissionSettings& s) {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  std::string who = s.operator_name;
  if (who.empty()) who = std::getenv("USER") ? std::getenv("USER") : "(unknown: set --operator)";
  return "<p>" + std::string(date) + "; robodamp " + rt::version() + " (" + rt::git_commit() + "); operator " +
         esc(who) + "; configuration SHA-256 <code>" + sha256_hex(read_text(s.config_path)) + "</code></p>\n";
}

}  // namespace

std::string write_report(const CommissionSettings& s, const CommissionResult& r, const std::string& path) {
  Plots p(fs::path(path).parent_path() / "plots");
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>robodamp commission: " << esc(s.config_path)
    << "</"
       "title>\n<style>body{font-family:sans-serif;max-width:1250px;margin:auto;padding:1em}table{border-collapse:"
       "collapse;"
       "margin:0.5em 0}td,th{border:1px solid #bbb;padding:3px "
       "8px;text-align:right}th{background:#eee}td:first-child{text-align:left}"
       ".ok{color:#1e8449}.warn{color:#b36b00}.bad{color:#c0392b;font-weight:bold}.banner{padding:0.6em;font-size:1."
       "2em;border-radius:4px}"
       ".pass{background:#d5f5e3}.fail{background:#fadbd8}img{max-width:100%}code{background:#f4f4f4}</style></"
       "head><body>\n";
  h << "<h1>robodamp commission</h1>\n<p>Cell <code>" << esc(s.config_path) << "</code>, job <code>" << esc(s.job_path)
    << "</code>.<br>Command: <code>" << esc(s.command_line) << "</code></p>\n"
    << provenance(s);
  if (r.outcome == Outcome::kVerified)
    h << "<p class=\"banner pass\">VERIFIED: " << esc(r.configuration_path) << " written.</p>\n";
  else
    h << "<p class=\"banner fail\">NOT VERIFIED: stopped at the " << to_string(r.stage) << " stage: " << esc(r.reason)
      << ". Nothing written as configuration.yaml.</p>\n";
  h << cut_section(r, p);
  h << "<h2>1. Stages</h2>\n<table><tr><th>stage</th><th>wall time (s)</th><th></th></tr>\n";
  for (const auto& t : r.times)
    h << "<tr><td>" << to_string(t.stage) << "</td><td>" << fmt("%.1f", t.wall_s) << "</td><td>"
      << (t.reused ? "reused from the directory" : "") << "</td></tr>\n";
  h << "<tr><td>total</td><td>" << fmt("%.1f", r.wall_s) << "</td><td></td></tr></table>\n";
  if (r.identified) h << identified_section(*r.identified, p);
  h << tuned_section(r) << verify_section(r, p) << "</body></html>\n";
  std::ofstream out(path);
  out << h.str();
  if (!out) return "cannot write " + path;
  return {};
}

}  // namespace robodamp::commission
