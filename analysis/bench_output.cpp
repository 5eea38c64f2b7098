#include "analysis/bench_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "analysis/loop_report.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::analysis {

using nlohmann::json;

namespace {
json opt(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }
std::string pct(const std::optional<double>& v) {
  if (!v) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.1f %%", *v);
  return b;
}
}  // namespace

json bench_report_json(const Bench& bench, const BenchReport& r) {
  const auto& cfg = bench.model().config();
  json j;
  j["config"] = r.config;
  j["analysis"] = analysis_report(bench.model(), r.analysis);
  j["settings"] = {{"loop_rate_hz", cfg.loop.rate_hz},
                   {"oversampling", cfg.plant.oversampling},
                   {"averages", cfg.bench.averages},
                   {"record_s", cfg.bench.record_s},
                   {"resolution_hz", 1.0 / cfg.bench.record_s},
                   {"evaluation_grid_hz", 1.0 / (cfg.bench.record_s * cfg.bench.zero_pad)},
                   {"impact_peak_n", cfg.bench.impact_peak_n},
                   {"impact_duration_ms", cfg.bench.impact_duration_ms},
                   {"saturating_impact_peak_n", cfg.bench.saturating_impact_peak_n},
                   {"sensor_noise_density_ug_per_rthz", cfg.sensor.noise_density_ug_per_rthz},
                   {"drives_on", cfg.disturbances.drives_on},
                   {"drive_vibration_hz", cfg.disturbances.drive_vibration_hz},
                   {"drive_vibration_mps2", cfg.disturbances.drive_vibration_mps2},
                   {"band_hz", {cfg.analysis.band_min_hz, cfg.analysis.band_max_hz}},
                   {"seed", cfg.disturbances.seed}};
  j["open_loop_check"] = json::array();
  for (const auto& o : r.open_loop)
    j["open_loop_check"].push_back({{"name", o.name},
                                    {"model_peak_m_per_n", o.model_peak_m_per_n},
                                    {"measured_peak_m_per_n", o.measured_peak_m_per_n},
                                    {"error_db", o.error_db},
                                    {"coherence_min", o.coherence_min}});
  j["rows"] = json::array();
  for (const auto& row : r.rows)
    j["rows"].push_back(
        {{"name", row.name},
         {"kind", row.kind},
         {"control_gain_ns_per_m", row.gain_ns_per_m},
         {"impact_peak_n", row.impact_peak_n},
         {"measured_improvement_pct", opt(row.measured_improvement_pct)},
         {"predicted_improvement_pct", opt(row.predicted_improvement_pct)},
         {"predicted_continuous_improvement_pct", opt(row.predicted_continuous_improvement_pct)},
         {"saturated", row.saturated},
         {"saturation_time_s", row.saturation_time_s},
         {"peak_actuator_force_n", row.peak_actuator_force_n},
         {"coherence_min", row.measured_improvement_pct ? json(row.coherence_min) : json(nullptr)},
         {"open_peak_m_per_n", row.measured_improvement_pct ? json(row.open.magnitude_m_per_n) : json(nullptr)},
         {"closed_peak_m_per_n", row.measured_improvement_pct ? json(row.closed.magnitude_m_per_n) : json(nullptr)},
         {"closed_peak_freq_hz", row.measured_improvement_pct ? json(row.closed.freq_hz) : json(nullptr)}});
  j["sweep"] = json::array();
  for (const auto& d : r.sweep)
    j["sweep"].push_back({{"control_gain_ns_per_m", d.gain_ns_per_m},
                          {"predicted_unstable", d.predicted_unstable},
                          {"predicted_growth_per_s", d.predicted_growth_per_s},
                          {"diverged", d.diverged},
                          {"measured_growth_per_s",
                           std::isfinite(d.measured_growth_per_s) ? json(d.measured_growth_per_s) : json(nullptr)},
                          {"final_window_saturated", d.final_window_saturated},
                          {"end_to_start_rms_ratio", d.growth_ratio},
                          {"saturation_time_s", d.saturation_time_s}});
  j["simulated_s"] = r.simulated_s;
  j["wall_s"] = r.wall_s;
  j["improvement_within_5pct"] = r.improvement_within_5pct;
  j["sweep_agrees"] = r.sweep_agrees;
  j["verdict"] = r.verdict;
  j["notes"] = r.notes;
  return j;
}

std::string bench_table(const Bench& bench, const BenchReport& r) {
  const auto& cfg = bench.model().config();
  std::ostringstream os;
  char line[320];
  os << analysis_table(analysis_report(bench.model(), r.analysis)) << "\n";
  std::snprintf(line, sizeof line,
                "Impact tests: %d averages x %.0f s records (resolution %.3f Hz, evaluated on a %.4f Hz zero-padded "
                "grid), H1 estimator;\n  sensor noise %.1f ug/sqrt(Hz), drives %s (%.1f Hz, %.3f m/s^2), seed %llu\n",
                cfg.bench.averages, cfg.bench.record_s, 1.0 / cfg.bench.record_s,
                1.0 / (cfg.bench.record_s * cfg.bench.zero_pad), cfg.sensor.noise_density_ug_per_rthz,
                cfg.disturbances.drives_on ? "on" : "off", cfg.disturbances.drive_vibration_hz,
                cfg.disturbances.drive_vibration_mps2, static_cast<unsigned long long>(cfg.disturbances.seed));
  os << line;
  os << "Open-loop FRFs from impacts against the modal model:\n";
  for (const auto& o : r.open_loop) {
    std::snprintf(line, sizeof line, "  %-10s model peak %.4g m/N, measured %.4g m/N (%+.3f dB), coherence min %.4f\n",
                  o.name.c_str(), o.model_peak_m_per_n, o.measured_peak_m_per_n, o.error_db, o.coherence_min);
    os << line;
  }
  std::snprintf(line, sizeof line, "\n  %-10s %-10s %8s %9s %10s %10s %12s %9s %9s %10s %9s\n", "FRF", "kind",
                "K N s/m", "impact N", "measured", "predicted", "(continuous)", "saturated", "sat. s", "peak F N",
                "coh. min");
  os << line;
  for (const auto& row : r.rows) {
    std::snprintf(line, sizeof line, "  %-10s %-10s %8.0f %9.0f %10s %10s %12s %9s %9.3f %10.2f %9s\n",
                  row.name.c_str(), row.kind.c_str(), row.gain_ns_per_m, row.impact_peak_n,
                  pct(row.measured_improvement_pct).c_str(), pct(row.predicted_improvement_pct).c_str(),
                  pct(row.predicted_continuous_improvement_pct).c_str(), row.saturated ? "yes" : "no",
                  row.saturation_time_s, row.peak_actuator_force_n,
                  row.measured_improvement_pct ? std::to_string(row.coherence_min).substr(0, 6).c_str() : "-");
    os << line;
  }
  if (!r.sweep.empty()) {
    os << "\nGain sweep (impact at the actuator, " << cfg.bench.sweep_duration_s << " s each):\n";
    for (const auto& d : r.sweep) {
      char growth[64];
      if (std::isfinite(d.measured_growth_per_s))
        std::snprintf(growth, sizeof growth, "growth %+.3f 1/s", d.measured_growth_per_s);
      else
        std::snprintf(growth, sizeof growth, "at its limit too soon to fit");
      std::snprintf(line, sizeof line,
                    "  K = %8.0f N s/m: predicted %-8s (growth %+.3f 1/s), simulated %-8s (%s, end/start RMS %.3g%s)\n",
                    d.gain_ns_per_m, d.predicted_unstable ? "unstable" : "stable", d.predicted_growth_per_s,
                    d.diverged ? "diverges" : "decays", growth, d.growth_ratio,
                    d.final_window_saturated ? ", saturated at the end" : "");
      os << line;
    }
  }
  bool saturating = false;
  for (const auto& row : r.rows) saturating = saturating || (row.kind == "saturating" && row.saturated);
  if (saturating)
    os << "\nSaturating rows: the " << cfg.bench.saturating_impact_peak_n
       << " N impacts drive the force command into the " << cfg.actuator.force_limit_n
       << " N actuator limit; clipped feedback adds less damping than the linear analysis\n"
       << "assumes, so the measured improvement falls below the prediction (the paper's experiments saturated at 36 "
          "N).\n"
       << "'peak F' is the force transmitted to the structure (Eq. 3); the limit acts on the commanded coil force T "
          "V,\n"
       << "which near the actuator's own resonance is transmitted up to 1 / (2 zeta_a) times larger.\n";
  for (const auto& n : r.notes) os << "note: " << n << "\n";
  std::snprintf(line, sizeof line, "\n%.0f s simulated in %.2f s wall (%.0fx real time)\n", r.simulated_s, r.wall_s,
                r.simulated_s / r.wall_s);
  os << line;
  return os.str();
}

std::string plot_bench(const Bench& bench, const BenchReport& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!r.sweep.empty()) {
    std::ostringstream data, s;
    std::size_t n = 0;
    for (const auto& d : r.sweep) n = std::max(n, d.envelope_v.size());
    for (std::size_t w = 0; w < n; ++w) {
      data << (static_cast<double>(w) + 0.5) * r.sweep.front().window_s;
      for (const auto& d : r.sweep)
        data << ' ' << (w < d.envelope_v.size() && d.envelope_v[w] > 0 ? d.envelope_v[w] : NAN);
      data << '\n';
    }
    s << "set title 'Gain sweep in the time domain: command RMS after an impact'\nset logscale y\nset grid\n"
         "set xlabel 'time (s)'\nset ylabel 'command RMS (V)'\nset key outside right\nplot ";
    for (std::size_t i = 0; i < r.sweep.size(); ++i) {
      char t[128];
      std::snprintf(t, sizeof t, "K = %.0f (%s)", r.sweep[i].gain_ns_per_m,
                    r.sweep[i].predicted_unstable ? "predicted unstable" : "predicted stable");
      s << (i ? ", " : "") << "DATA u 1:" << 2 + i << " w l lw 2 t '" << t << "'";
    }
    s << "\n";
    if (auto e = plot::run_gnuplot(s.str(), data.str(), dir + "/bench_sweep.png"); !e.empty()) return e;
  }
  {
    std::ostringstream data, s;
    int i = 0;
    for (const auto& row : r.rows) {
      if (!row.measured_improvement_pct) continue;
      data << i++ << " \"" << row.name << "\\n"
           << row.kind << "\\nK " << static_cast<int>(row.gain_ns_per_m) << "\" " << *row.measured_improvement_pct
           << ' ' << row.predicted_improvement_pct.value_or(NAN) << '\n';
    }
    s << "set title 'Dynamic stiffness improvement: bench (measured) vs analysis (predicted)'\nset style data "
         "histogram\n"
         "set style histogram clustered gap 1\nset style fill solid 0.8 border -1\nset grid ytics\n"
         "set ylabel 'improvement (%)'\nset xtics rotate by -45 font ',8'\nset key top right\n"
         "plot DATA u 3:xtic(2) t 'measured', DATA u 4 t 'predicted (discrete loop)'\n";
    if (auto e = plot::run_gnuplot(s.str(), data.str(), dir + "/bench_improvement.png"); !e.empty()) return e;
  }
  (void)bench;
  return {};
}

}  // namespace robodamp::analysis
