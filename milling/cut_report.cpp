#include "milling/cut_report.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <sstream>

#include "analysis/fft.hpp"
#include "fields/json.hpp"
#include "milling/chatter.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::milling {

using nlohmann::json;

using fields::finite_or_null;

json cut_json(const CutJob& job, const CutOutcome& o, double wall_s) {
  const auto& r = o.record;
  const auto& v = o.verdict;
  return {{"rpm", r.rpm},
          {"axial_mm", job.settings.cut.axial_mm},
          {"radial_mm", job.settings.cut.radial_mm},
          {"stable", v.stable},
          {"classification", to_string(v.classification)},
          {"mechanism", to_string(v.mechanism)},
          {"chatter_hz", v.stable ? json(nullptr) : json(v.chatter_hz)},
          {"chatter_family_hz",
           v.stable ? json(nullptr) : json(chatter_family_hz(v.chatter_hz, r.rpm * job.cutter.teeth / 60.0))},
          {"once_per_tooth_ratio", v.once_per_period_ratio},
          {"nonharmonic_energy_ratio", v.nonharmonic_energy_ratio},
          {"growth_per_tooth", finite_or_null(v.growth_per_period)},
          {"out_of_cut_share", v.out_of_cut_share},
          {"peak_force_n", r.peak_force_n},
          {"peak_actuator_force_n", finite_or_null(r.peak_actuator_force_n)},
          {"actuator_saturated", r.actuator_saturated_s > 0.0},
          {"actuator_saturated_s", r.actuator_saturated_s},
          {"damped", job.damped},
          {"requested_rpm", job.requested_rpm},
          {"sle_um", finite_or_null(r.sle_um)},
          {"steps_per_tooth", r.steps_per_tooth},
          {"step_s", r.step_s},
          {"simulated_s", r.step_s * static_cast<double>(r.x_m.size())},
          {"wall_s", wall_s}};
}

std::string plot_cut(const CutOutcome& o, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const auto& r = o.record;
  const std::size_t from = r.settle_steps, n = r.x_m.size();
  {  // displacement and force after settling
    std::ostringstream d;
    for (std::size_t k = from; k < n; ++k)
      d << static_cast<double>(k) * r.step_s << ' ' << r.x_m[k] * 1e6 << ' ' << r.y_m[k] * 1e6 << ' ' << r.fx_n[k]
        << ' ' << r.fy_n[k] << '\n';
    const std::string s1 =
        "set title 'Tool displacement (cutter frame)'\nset grid\nset xlabel 'time (s)'\nset ylabel 'um'\n"
        "plot DATA u 1:2 w l t 'x (feed)', DATA u 1:3 w l t 'y (wall normal)'\n";
    if (auto e = plot::run_gnuplot(s1, d.str(), dir + "/cut_displacement.png"); !e.empty()) return e;
    const std::string s2 =
        "set title 'Cutting force on the tool'\nset grid\nset xlabel 'time (s)'\nset ylabel 'N'\n"
        "plot DATA u 1:4 w l t 'Fx', DATA u 1:5 w l t 'Fy'\n";
    if (auto e = plot::run_gnuplot(s2, d.str(), dir + "/cut_force.png"); !e.empty()) return e;
  }
  {  // spectrum of y after settling, tooth-passing harmonics marked
    const std::size_t len =
        ((n - from) / static_cast<std::size_t>(r.steps_per_tooth)) * static_cast<std::size_t>(r.steps_per_tooth);
    analysis::RealFft fft(len);
    double mean = 0.0;
    for (std::size_t i = 0; i < len; ++i) mean += r.y_m[n - len + i] / static_cast<double>(len);
    for (std::size_t i = 0; i < len; ++i) fft.input()[i] = r.y_m[n - len + i] - mean;
    const std::complex<double>* x = fft.forward();
    const double df = 1.0 / (r.step_s * static_cast<double>(len)), tooth_hz = r.rpm * r.teeth / 60.0;
    const double f_max = std::min(0.5 / r.step_s, 8.0 * tooth_hz + 2.0 * o.verdict.chatter_hz);
    std::ostringstream d, s;
    for (std::size_t k = 1; k < fft.bins() && static_cast<double>(k) * df <= f_max; ++k)
      d << static_cast<double>(k) * df << ' ' << 2.0 * std::abs(x[k]) / static_cast<double>(len) * 1e6 << '\n';
    s << "set title 'Spectrum of the wall-normal displacement (" << to_string(o.verdict.classification)
      << ")'\nset grid\nset logscale y\nset xlabel 'frequency (Hz)'\nset ylabel 'amplitude (um)'\n";
    for (int h = 1; h * tooth_hz <= f_max; ++h)
      s << "set arrow from " << h * tooth_hz << ", graph 0 to " << h * tooth_hz
        << ", graph 1 nohead dt 3 lc rgb 'gray50'\n";
    s << "plot DATA u 1:2 w l lw 2 t 'y (tooth-passing harmonics dotted)'\n";
    if (auto e = plot::run_gnuplot(s.str(), d.str(), dir + "/cut_spectrum.png"); !e.empty()) return e;
  }
  {  // the machined wall per revolution
    std::ostringstream d;
    for (std::size_t i = 0; i < r.wall_per_rev_um.size(); ++i) d << i << ' ' << r.wall_per_rev_um[i] << '\n';
    const std::string s =
        "set title 'Machined wall: surface location error per revolution (+ = undercut)'\nset grid\n"
        "set xlabel 'revolution after settling'\nset ylabel 'um'\nplot DATA u 1:2 w lp t 'SLE'\n";
    if (auto e = plot::run_gnuplot(s, d.str(), dir + "/cut_surface.png"); !e.empty()) return e;
  }
  return {};
}

}  // namespace robodamp::milling
