#include "milling/cut_report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <filesystem>
#include <sstream>

#include "analysis/fft.hpp"
#include "fields/json.hpp"
#include "fields/printf.hpp"
#include "milling/chatter.hpp"
#include "milling/cut_stability.hpp"
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

namespace {

// Beside a frequency the simulated cut found, how it relates to the accurate method's (milling/chatter.hpp).
const char* alias_note(double cut_hz, double accurate_hz, double tooth_hz) {
  // Within 0.5 % of the larger (the frequency moves with the depth) and 1 % of the tooth frequency.
  const double tol_hz = 0.005 * std::max(std::abs(cut_hz), std::abs(accurate_hz)) + 0.01 * tooth_hz;
  if (std::abs(cut_hz - accurate_hz) <= tol_hz) return "";
  return same_chatter(cut_hz, accurate_hz, tooth_hz, tol_hz) ? " (another alias of the same chatter)"
                                                             : " (not the accurate method's chatter)";
}

}  // namespace

std::string cut_lines(const CutJob& job, const CutOutcome& o, const nlohmann::json& out) {
  using fields::printf_string;
  std::string t =
      printf_string("%s cut at %.1f rpm, %.3f mm axial, %.3f mm radial: %s", job.damped ? "damped" : "open-loop",
                    out["rpm"].get<double>(), out["axial_mm"].get<double>(), out["radial_mm"].get<double>(),
                    out["classification"].get<std::string>().c_str());
  if (!o.verdict.stable)
    t += printf_string(" (%s) at %.1f Hz", out["mechanism"].get<std::string>().c_str(), o.verdict.chatter_hz);
  t += printf_string(
      "; off-harmonic energy %.3f, once-per-tooth ratio %.3g, peak force %.1f N, SLE %.2f um; %.1f s simulated in %.2f "
      "s\n",
      o.verdict.nonharmonic_energy_ratio, o.verdict.once_per_period_ratio, o.record.peak_force_n, o.record.sle_um,
      out["simulated_s"].get<double>(), out["wall_s"].get<double>());
  if (job.damped)
    t += printf_string(
        "  damper: peak actuator force %.1f N, at a limit for %.3f s%s (speed %.1f rpm: the tooth period a whole "
        "number of loop periods)\n",
        o.record.peak_actuator_force_n, o.record.actuator_saturated_s,
        o.record.actuator_saturated_s > 0.0 ? " (SATURATED)" : "", o.record.rpm);
  return t;
}

CriticalAtSpeed critical_at_speed(const config::MillingConfig& cfg, const CutJob& job, const LobeModel& lobes,
                                  const AccurateStability& truth, double rpm, bool damped,
                                  const std::function<void(const std::string&)>& progress) {
  const double zoa_mm = lobes.critical_depth_mm(rpm);
  SdmPoint sdm;
  try {
    sdm = truth.critical(rpm, zoa_mm);
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError({config::Problem{cfg.source, {}, "--rpm", e.what()}});
  }
  std::ostringstream head;
  head << "critical depth at " << rpm << " rpm (" << truth.method() << " " << sdm.critical_depth_mm
       << " mm, zero-order preview " << zoa_mm << " mm):";
  progress(head.str());
  const auto t0 = std::chrono::steady_clock::now();
  const double guess = std::isfinite(sdm.critical_depth_mm) ? sdm.critical_depth_mm
                       : std::isfinite(zoa_mm)              ? zoa_mm
                                                            : 1.0;
  const CriticalDepth c = critical_depth(job.dynamics, job.cutter, job.material, job.settings, guess, 2e-3, progress);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double tooth_hz = rpm * job.cutter.teeth / 60.0;  // the chatter's family: milling/chatter.hpp
  CriticalAtSpeed out;
  out.depth_mm = c.depth_mm;
  out.entry = {{"rpm", rpm},
               {"simulated_rpm", job.settings.rpm},
               {"damped", damped},
               {"critical_depth_mm", c.depth_mm},
               {"lobes_b_lim_mm", fields::finite_or_null(zoa_mm)},
               {"accurate_method", truth.method()},
               {"accurate_b_lim_mm", fields::finite_or_null(sdm.critical_depth_mm)},
               {"accurate_rpm", sdm.rpm},
               {"accurate_chatter_hz", sdm.chatter_hz},
               {"accurate_chatter_family_hz", chatter_family_hz(sdm.chatter_hz, tooth_hz)},
               {"chatter_family_hz", chatter_family_hz(c.chatter_hz, tooth_hz)},
               {"accurate_type", to_string(sdm.type)},
               {"classification", to_string(c.above)},
               {"mechanism", to_string(c.mechanism)},
               {"chatter_hz", c.chatter_hz},
               {"simulations", c.simulations},
               {"wall_s", wall}};
  out.line = fields::printf_string(
      "%8.0f rpm: time-domain critical depth %.4f mm (%s %.4f mm %+.1f %%, %s at %.1f Hz; zero-order preview %.4f mm), "
      "above it %s (%s) at %.1f Hz%s; %d cuts in %.2f s\n",
      rpm, c.depth_mm, truth.method().c_str(), sdm.critical_depth_mm,
      (sdm.critical_depth_mm / c.depth_mm - 1.0) * 100.0, to_string(sdm.type), sdm.chatter_hz, zoa_mm,
      to_string(c.above), to_string(c.mechanism), c.chatter_hz, alias_note(c.chatter_hz, sdm.chatter_hz, tooth_hz),
      c.simulations, wall);
  return out;
}

nlohmann::json critical_study(
    const config::MillingConfig& cfg, const CriticalStudy& study,
    const std::function<void(const std::string&)>& progress,
    const std::function<nlohmann::json(const CutJob&, double, const CriticalAtSpeed&)>& more) {
  // The accurate verdict (what lobes and tune promise) beside the simulation, and its first guess.
  const Structure model_structure(study.chosen, study.damped);
  const LobeModel lobes(model_structure, chatter_process(cfg.tool, cfg.material, cfg.cut), cfg.lobes);
  config::MillingConfig at_cut = cfg;
  if (study.radial_mm) at_cut.cut.radial_mm = *study.radial_mm;
  const AccurateStability truth(model_structure, at_cut);
  nlohmann::json out = nlohmann::json::array();
  CutOverrides ov = study.overrides;
  for (double rpm : study.speeds) {
    ov.rpm = rpm;
    const CutJob job = make_cut_job(cfg, study.structure, ov);
    CriticalAtSpeed c = critical_at_speed(cfg, job, lobes, truth, rpm, study.damped, progress);
    std::fputs(c.line.c_str(), stdout);
    if (nlohmann::json extra = more(job, rpm, c); !extra.is_null()) c.entry["hil"] = std::move(extra);
    out.push_back(std::move(c.entry));
  }
  return out;
}

}  // namespace robodamp::milling
