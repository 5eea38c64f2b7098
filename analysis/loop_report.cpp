#include "analysis/loop_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "fields/json.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::analysis {

using nlohmann::json;

namespace {

using fields::number_or_null;

json frf_json(const FrfResult& f, bool stable) {
  return {{"name", f.name},
          {"open_peak_m_per_n", f.open_peak_m_per_n},
          {"open_peak_freq_hz", f.open_peak_freq_hz},
          {"closed_peak_m_per_n", stable ? json(f.closed_peak_m_per_n) : json(nullptr)},
          {"peak_freq_hz", stable ? json(f.peak_freq_hz) : json(nullptr)},
          {"improvement_pct", stable ? json(f.improvement_pct) : json(nullptr)}};
}

using fields::number_text;

}  // namespace

json analysis_report(const LoopModel& m, const AnalysisResult& r) {
  json j;
  j["config"] = m.config().source;
  j["loop_rate_hz"] = m.loop_rate_hz();
  j["gain_ns_per_m"] = r.gain_ns_per_m;
  j["polarity"] = r.polarity;
  j["stable"] = r.stable;
  j["stable_continuous"] = r.stable_continuous;
  j["spectral_radius"] = r.spectral_radius;
  j["nyquist_encirclements"] = r.nyquist_encirclements;
  j["max_stable_gain_ns_per_m"] = number_or_null(r.max_stable_gain_ns_per_m);
  j["gain_margin_db"] = number_or_null(r.margins.gain_margin_db);
  j["phase_margin_deg"] = number_or_null(r.margins.phase_margin_deg);
  j["delay_margin_ms"] = number_or_null(r.margins.delay_margin_ms);
  j["gain_crossover_hz"] = number_or_null(r.margins.gain_crossover_hz);
  j["phase_crossover_hz"] = number_or_null(r.margins.phase_crossover_hz);
  j["recommended_polarity"] = r.recommended_polarity;
  j["polarity_reason"] = r.polarity_reason;
  j["modes"] = json::array();
  for (const auto& mp : r.modes)
    j["modes"].push_back({{"freq_hz", mp.freq_hz},
                          {"feedback_phase_deg", mp.feedback_phase_deg},
                          {"damps", mp.damps},
                          {"notch_phase_deg", std::arg(m.notch_response(mp.freq_hz)) * 180.0 / M_PI}});
  if (m.spindle_rpm()) {
    const double teeth = m.config().spindle.teeth;
    j["spindle"] = {{"rpm", *m.spindle_rpm()},
                    {"teeth", teeth},
                    {"tooth_hz", *m.spindle_rpm() * teeth / 60.0},
                    {"notches", m.notch_count()}};
  }
  j["frfs"] = json::array();  // the discrete loop that runs
  for (const auto& f : r.frfs_discrete) j["frfs"].push_back(frf_json(f, r.stable));
  j["frfs_continuous"] = json::array();  // docs/physics.md §1 equations, delay exact
  for (const auto& f : r.frfs_continuous) j["frfs_continuous"].push_back(frf_json(f, r.stable_continuous));
  j["quiet_command_rms_v"] = r.quiet_command_rms_v;
  j["quiet_command_peak_hz"] = r.quiet_command_peak_hz;
  j["notes"] = r.notes;
  return j;
}

std::string analysis_table(const json& r) {
  std::ostringstream os;
  char line[256];
  os << "Closed-loop analysis of " << r["config"].get<std::string>() << " (K = " << r["gain_ns_per_m"].get<double>()
     << " N s/m, polarity " << std::showpos << r["polarity"].get<int>() << std::noshowpos << ", "
     << r["loop_rate_hz"].get<double>() << " Hz)\n";
  os << "  discrete loop:   " << (r["stable"].get<bool>() ? "STABLE" : "UNSTABLE") << " (spectral radius "
     << number_text(r["spectral_radius"], "%.6f") << ", Nyquist encirclements " << r["nyquist_encirclements"].get<int>()
     << ")\n";
  os << "  continuous loop: " << (r["stable_continuous"].get<bool>() ? "stable" : "unstable") << "\n";
  os << "  max stable K " << number_text(r["max_stable_gain_ns_per_m"], "%.1f") << " N s/m, gain margin "
     << number_text(r["gain_margin_db"], "%.2f") << " dB, "
     << (r["gain_crossover_hz"].is_null()
             ? std::string("no gain crossover (the loop gain stays below 1: no phase margin to state)")
             : "phase margin " + number_text(r["phase_margin_deg"], "%.1f") + " deg at " +
                   number_text(r["gain_crossover_hz"], "%.2f") + " Hz")
     << ", delay margin " << number_text(r["delay_margin_ms"], "%.2f") << " ms\n";
  if (!r["gain_margin_db"].is_null() && r["gain_margin_db"].get<double>() < 6.0)
    os << "  WARNING: gain margin " << number_text(r["gain_margin_db"], "%.2f") << " dB, below 6 dB\n";
  if (!r["phase_margin_deg"].is_null() && r["phase_margin_deg"].get<double>() < 45.0)
    os << "  WARNING: phase margin " << number_text(r["phase_margin_deg"], "%.1f") << " deg, below 45 deg\n";
  if (r.contains("spindle")) {
    const auto& sp = r["spindle"];
    std::snprintf(line, sizeof line, "  spindle %.0f rpm x %.0f teeth = %.2f Hz: %zu harmonic notches in the loop\n",
                  sp["rpm"].get<double>(), sp["teeth"].get<double>(), sp["tooth_hz"].get<double>(),
                  sp["notches"].get<std::size_t>());
    os << line;
    for (const auto& mp : r["modes"]) {
      std::snprintf(line, sizeof line, "    the notches' phase at %.2f Hz: %+.3f deg\n", mp["freq_hz"].get<double>(),
                    mp["notch_phase_deg"].get<double>());
      os << line;
    }
  }
  if (r.contains("job_limits")) {
    const auto& l = r["job_limits"];
    auto mm = [](const json& v) {
      return v.is_null() ? std::string("none below 1 m") : number_text(v, "%.3f") + " mm";
    };
    os << "  the job (spindle.job) at " << number_text(l["rpm"], "%.0f") << " rpm, depth "
       << number_text(l["depth_mm"], "%.3f") << " mm: limit open " << mm(l["open_mm"]) << " ("
       << l["open_method"].get<std::string>() << "), damped " << mm(l["damped_mm"]) << " ("
       << l["damped_method"].get<std::string>() << " at " << number_text(l["analysed_rpm"], "%.2f") << " rpm)\n";
  }
  if (r["stable"].get<bool>())
    os << "  quiet cell: command " << number_text(r["quiet_command_rms_v"], "%.4f") << " V RMS (density peak at "
       << number_text(r["quiet_command_peak_hz"], "%.2f") << " Hz; sensor noise, ADC, drive vibration)\n";
  os << "  recommended polarity " << std::showpos << r["recommended_polarity"].get<int>() << std::noshowpos << ": "
     << r["polarity_reason"].get<std::string>() << "\n";
  for (const auto& mp : r["modes"]) {
    const bool edge = mp["damps"].get<bool>() && std::abs(mp["feedback_phase_deg"].get<double>()) > 80.0;
    std::snprintf(line, sizeof line, "    mode %6.2f Hz: feedback force at %7.1f deg from -velocity: %s%s\n",
                  mp["freq_hz"].get<double>(), mp["feedback_phase_deg"].get<double>(),
                  mp["damps"].get<bool>() ? "damps" : "does NOT damp",
                  edge ? " (WARNING: within 10 deg of the damping window's edge at 90 deg)" : "");
    os << line;
  }
  std::snprintf(line, sizeof line, "  %-22s %14s %10s %14s %10s %12s %14s\n", "FRF", "open peak m/N", "at Hz",
                "closed peak", "at Hz", "improvement", "(continuous)");
  os << line;
  for (std::size_t i = 0; i < r["frfs"].size(); ++i) {
    const auto& f = r["frfs"][i];
    const auto& c = r["frfs_continuous"][i];
    std::snprintf(line, sizeof line, "  %-22s %14s %10s %14s %10s %11s%% %13s%%\n",
                  f["name"].get<std::string>().c_str(), number_text(f["open_peak_m_per_n"], "%.4g").c_str(),
                  number_text(f["open_peak_freq_hz"], "%.2f").c_str(),
                  number_text(f["closed_peak_m_per_n"], "%.4g").c_str(), number_text(f["peak_freq_hz"], "%.2f").c_str(),
                  number_text(f["improvement_pct"], "%.1f").c_str(), number_text(c["improvement_pct"], "%.1f").c_str());
    os << line;
  }
  for (const auto& n : r["notes"]) os << "  note: " << n.get<std::string>() << "\n";
  return os.str();
}

std::string plot_analysis(const LoopModel& m, const AnalysisResult& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const auto& cfg = m.config();
  const double k = r.gain_ns_per_m;
  const int pol = r.polarity;
  // 1. FRFs open vs closed (discrete loop), each configured path.
  {
    std::ostringstream data;
    const double lo = 1.0, hi = std::min(100.0, 0.45 * m.loop_rate_hz());
    for (int i = 0; i <= 1500; ++i) {
      const double f = lo * std::pow(hi / lo, i / 1500.0);
      const auto p = m.plant_response(f);
      const auto c = m.chain_filters_digital(f);
      data << f;
      for (const auto& fr : r.frfs_discrete)
        data << ' ' << std::abs(m.open_discrete(p, fr.response, fr.excitation)) << ' '
             << std::abs(m.closed_discrete(p, c, fr.response, fr.excitation, k, pol));
      data << '\n';
    }
    std::ostringstream s;
    s << "set title 'Receptance, control off vs on (K = " << k << " N s/m, polarity " << pol << ")"
      << (r.stable ? "" : " UNSTABLE")
      << "'\nset logscale xy\nset grid\nset xlabel 'frequency (Hz)'\nset ylabel '|H| (m/N)'\nset key top right\nplot ";
    for (std::size_t i = 0; i < r.frfs_discrete.size(); ++i)
      s << (i ? ", " : "") << "DATA u 1:" << 2 + 2 * i << " w l lw 1.5 dt 2 lc " << i + 1 << " t '"
        << r.frfs_discrete[i].name << " open', DATA u 1:" << 3 + 2 * i << " w l lw 2 lc " << i + 1 << " t '"
        << r.frfs_discrete[i].name << " closed'";
    s << "\n";
    if (auto e = plot::run_gnuplot(s.str(), data.str(), dir + "/frf_open_closed.png"); !e.empty()) return e;
  }
  // 2. Nyquist of the discrete loop L (closed loop = 1/(1 + L)).
  {
    std::ostringstream data;
    for (int i = 0; i <= 6000; ++i) {
      const double f = 0.2 * std::pow(0.49 * m.loop_rate_hz() / 0.2, i / 6000.0);
      const auto l = m.loop_discrete(f, k, pol);
      data << l.real() << ' ' << l.imag() << ' ' << l.real() << ' ' << -l.imag() << '\n';
    }
    std::ostringstream s;
    s << "set title 'Nyquist of the discrete loop L, K = " << k << " N s/m, polarity " << pol
      << "'\nset grid\nset size ratio -1\nset xlabel 'Re L'\nset ylabel 'Im L'\nset object 1 circle at 0,0 size 1 "
         "fc 'gray' dt 2\nset label 1 '-1' at -1,0 point pt 7 ps 1.5 lc 'red' offset 0.5,0.5\n"
         "plot DATA u 1:2 w l lw 2 t 'L(e^{jwT}), 0 < f < fs/2', DATA u 3:4 w l dt 2 lc 'gray' t 'mirror'\n";
    if (auto e = plot::run_gnuplot(s.str(), data.str(), dir + "/nyquist.png"); !e.empty()) return e;
  }
  // 3. Gain sweep: improvement and the least-damped closed-loop pole against K.
  {
    const double k_hi = r.max_stable_gain_ns_per_m ? 1.3 * *r.max_stable_gain_ns_per_m : 3.0 * k;
    std::vector<double> gains;
    for (int i = 1; i <= 60; ++i) gains.push_back(k_hi * i / 60.0);
    const auto sweep = gain_sweep(m, pol, gains);
    std::ostringstream data;
    for (const auto& p : sweep) {
      data << p.gain_ns_per_m << ' ' << p.spectral_radius << ' ' << p.least_damping_ratio << ' ' << p.least_damped_hz;
      for (double v : p.improvement_pct) data << ' ' << (p.spectral_radius < 1.0 ? v : NAN);
      data << '\n';
    }
    std::ostringstream s;
    s << "set multiplot layout 2,1 title 'Gain sweep (discrete loop, polarity " << pol << ")'\nset grid\n"
      << "set ylabel 'improvement (%)'\nset key top left\n";
    if (r.max_stable_gain_ns_per_m)
      s << "set arrow 1 from " << *r.max_stable_gain_ns_per_m << ", graph 0 to " << *r.max_stable_gain_ns_per_m
        << ", graph 1 nohead lc 'red' dt 2\n";
    s << "set arrow 2 from " << k << ", graph 0 to " << k << ", graph 1 nohead lc 'black' dt 3\nplot ";
    for (std::size_t i = 0; i < cfg.robot.frfs.size(); ++i)
      s << (i ? ", " : "") << "DATA u 1:" << 5 + i << " w lp pt 7 ps 0.5 t '" << cfg.robot.frfs[i].name << "'";
    s << "\nset xlabel 'K (N s/m)'\nset ylabel 'least damping ratio of the closed loop'\nset yrange [-0.05:*]\n"
         "plot DATA u 1:3 w lp pt 7 ps 0.5 lc 'black' t 'least-damped pole (zeta)', 0 w l lc 'red' notitle\n"
         "unset multiplot\n";
    if (auto e = plot::run_gnuplot(s.str(), data.str(), dir + "/gain_sweep.png"); !e.empty()) return e;
  }
  return {};
}

}  // namespace robodamp::analysis
