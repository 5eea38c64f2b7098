#include "analysis/chain_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "plot/gnuplot.hpp"

namespace robodamp::analysis {

using filters::Complex;
using filters::magnitude_db;
using filters::phase_deg;

namespace {

nlohmann::json bode_point(Complex h) { return {{"mag_db", magnitude_db(h)}, {"phase_deg", phase_deg(h)}}; }

}  // namespace

nlohmann::json filters_report(const ChainDesign& d, double freq_hz) {
  const auto& p = d.params;
  nlohmann::json blocks = nlohmann::json::array();
  for (std::size_t i = 0; i < d.blocks.size(); ++i) {
    const auto& b = d.blocks[i];
    const auto& g = d.groups[b.group];
    nlohmann::json j{{"name", b.name},
                     {"kind", config::to_string(b.kind)},
                     {"prewarp_hz", g.digital.prewarp_hz},
                     {"realised_as", g.label},
                     {"sections", g.digital.sections.size()},
                     {"analog", bode_point(b.analog.at_hz(freq_hz))},
                     {"digital", bode_point(d.block_digital(i, freq_hz))}};
    blocks.push_back(std::move(j));
  }
  const Complex k(p.gain_ns_per_m);
  blocks.push_back({{"name", "K"},
                    {"kind", "gain"},
                    {"unit", "N s/m"},
                    {"value", p.gain_ns_per_m},
                    {"analog", bode_point(k)},
                    {"digital", bode_point(k)}});
  const Complex out(p.polarity / p.actuator_constant_n_per_v);
  blocks.push_back({{"name", "polarity/T"},
                    {"kind", "gain"},
                    {"unit", "V/N"},
                    {"value", out.real()},
                    {"analog", bode_point(out)},
                    {"digital", bode_point(out)}});
  return {{"source", d.source},
          {"fs_hz", p.fs_hz},
          {"freq_hz", freq_hz},
          {"match_freq_hz", d.match_freq_hz},
          {"sections", p.sections.count},
          {"blocks", blocks},
          {"chain",
           {{"unit", "V per m/s^2"},
            {"analog", bode_point(d.chain_analog(freq_hz))},
            {"digital", bode_point(d.chain_digital(freq_hz))}}}};
}

std::string filters_table(const nlohmann::json& r) {
  std::ostringstream os;
  char line[256];
  os << "robodamp filters: " << r["source"].get<std::string>() << "\n  loop " << r["fs_hz"].get<double>() << " Hz, "
     << r["sections"].get<int>() << " second-order sections, response at " << r["freq_hz"].get<double>() << " Hz\n\n";
  std::snprintf(line, sizeof line, "  %-16s %-12s %11s %11s %11s %11s  %s\n", "block", "kind", "analog dB",
                "analog deg", "digital dB", "digital deg", "realised as (pre-warp)");
  os << line;
  auto row = [&](const nlohmann::json& b, const std::string& name, const std::string& kind, const std::string& note) {
    std::snprintf(line, sizeof line, "  %-16s %-12s %11.3f %11.2f %11.3f %11.2f  %s\n", name.c_str(), kind.c_str(),
                  b["analog"]["mag_db"].get<double>(), b["analog"]["phase_deg"].get<double>(),
                  b["digital"]["mag_db"].get<double>(), b["digital"]["phase_deg"].get<double>(), note.c_str());
    os << line;
  };
  for (const auto& b : r["blocks"]) {
    std::string note;
    if (b.contains("realised_as")) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "%s (%.3g Hz)", b["realised_as"].get<std::string>().c_str(),
                    b["prewarp_hz"].get<double>());
      note = buf;
    } else {
      note = "value " + std::to_string(b["value"].get<double>()) + " " + b["unit"].get<std::string>();
    }
    row(b, b["name"].get<std::string>(), b["kind"].get<std::string>(), note);
  }
  row(r["chain"], "chain", "V/(m/s^2)", "");
  return os.str();
}

std::string plot_filters(const ChainDesign& d, const std::string& png_path) {
  // Columns: f, then (mag, phase) of each block (analog), then the whole chain analog and digital in
  // volts per m/s^2 (with K, polarity and 1/T).
  std::ostringstream data;
  const double f_max = std::min(500.0, 0.45 * d.params.fs_hz);
  for (int i = 0; i <= 400; ++i) {
    const double f = 0.5 * std::pow(f_max / 0.5, i / 400.0);
    data << f;
    for (const auto& b : d.blocks) {
      const Complex h = b.analog.at_hz(f);
      data << ' ' << magnitude_db(h) << ' ' << phase_deg(h);
    }
    for (const Complex h : {d.chain_analog(f), d.chain_digital(f)})
      data << ' ' << magnitude_db(h) << ' ' << phase_deg(h);
    data << '\n';
  }
  std::ostringstream s;
  const std::size_t n = d.blocks.size();
  s << "set multiplot layout 2,1 title 'robodamp filter chain (" << d.source << "), fs = " << d.params.fs_hz
    << " Hz'\nset logscale x\nset grid\nset key outside right\nset xrange [0.5:" << f_max << "]\n"
    << "set arrow 1 from " << d.match_freq_hz << ", graph 0 to " << d.match_freq_hz
    << ", graph 1 nohead dt 2 lc 'gray'\n";  // the frequency the chain is matched at
  for (int panel = 0; panel < 2; ++panel) {
    s << (panel == 0 ? "set ylabel 'magnitude (dB)'\nset yrange [-60:40]\nunset xlabel\n"
                     : "set ylabel 'phase (deg)'\nset yrange [-180:180]\nset ytics 45\nset xlabel 'frequency (Hz)'\n");
    s << "plot ";
    for (std::size_t k = 0; k < n; ++k)
      s << "DATA u 1:" << 2 + 2 * k + panel << " w l lw 1.5 t '" << d.blocks[k].name << "', ";
    s << "DATA u 1:" << 2 + 2 * n + panel << " w l lw 3 lc 'black' t 'chain V/(m/s^2), analog', "
      << "DATA u 1:" << 4 + 2 * n + panel << " w l lw 2 dt 2 lc 'red' t 'chain, digital'\n";
  }
  s << "unset multiplot\n";
  return plot::run_gnuplot(s.str(), data.str(), png_path);
}

}  // namespace robodamp::analysis
