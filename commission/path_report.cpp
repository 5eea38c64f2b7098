#include "commission/path_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/pose_schedule.hpp"
#include "commission/path_commission.hpp"
#include "commission/stage_detail.hpp"
#include "hil/pose_trajectory.hpp"
#include "plot/gnuplot.hpp"
#include "rt/version.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using plot::num;

using detail::esc;
using detail::fmt;

std::string figure(const fs::path& dir, const std::string& name, const std::string& script, const std::string& data,
                   const std::string& caption) {
  fs::create_directories(dir);
  const fs::path png = dir / (name + ".png");
  std::ofstream(dir / (name + ".dat")) << data;
  if (const std::string e = plot::run_gnuplot(script, data, png.string()); !e.empty())
    return "<p class=bad>plot " + esc(name) + ": " + esc(e) + "</p>\n";
  return "<figure><img src=\"" + plot::png_data_uri(png.string()) + "\" alt=\"" + esc(caption) + "\"><figcaption>" +
         esc(caption) + "</figcaption></figure>\n";
}

// The joint that moves most along the stops (the plots' x axis).
std::size_t moving_joint(const std::vector<PathStop>& stops) {
  std::size_t best = 0;
  double span = -1.0;
  for (std::size_t j = 0; !stops.empty() && j < stops.front().joints_deg.size(); ++j) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& s : stops) lo = std::min(lo, s.joints_deg[j]), hi = std::max(hi, s.joints_deg[j]);
    if (hi - lo > span) span = hi - lo, best = j;
  }
  return best;
}

// The mapped modes along the path (the trajectory walked in joint space) with the modes measured at each
// stop: in the map as filled points, held out as open ones. Data: block 0 the sweep (joint, mode 1..n),
// block 1 the stops in the map (joint, Hz), block 2 the held-out stops.
std::string modes_figure(const PathCommissionSettings& s, const PathCommissionResult& r, const fs::path& dir) {
  if (r.mapped_model_path.empty() || r.stops.empty()) return {};
  const config::RobotModelConfig mapped = config::load_robot_model(r.mapped_model_path);
  const config::Config cell = config::load_config_file(s.config_path);
  const int axis = mapped.measured_modes ? mapped.measured_modes->axis : cell.pose_schedule->axis;
  const std::size_t j = moving_joint(r.stops);
  std::vector<hil::PoseWaypoint> path;
  for (const auto& item : s.trajectory) {
    hil::PoseWaypoint w;
    std::string error;
    if (hil::parse_waypoint(item, w, error)) path.push_back(std::move(w));
  }
  std::ostringstream d;
  std::size_t modes = 0;
  for (std::size_t w = 1; w < path.size(); ++w)
    for (int k = 0; k <= 20; ++k) {
      std::vector<double> q(path[w].joints_deg.size());
      for (std::size_t i = 0; i < q.size(); ++i)
        q[i] = path[w - 1].joints_deg[i] + (path[w].joints_deg[i] - path[w - 1].joints_deg[i]) * k / 20.0;
      const analysis::PoseModes pm = analysis::pose_modes(mapped, q, axis, cell.pose_schedule->modes);
      modes = std::max(modes, pm.modes.size());
      d << num(q[j]);
      for (const auto& m : pm.modes) d << ' ' << num(m.natural_freq_hz);
      d << '\n';
    }
  for (const bool held : {false, true}) {
    d << "\n\n";
    for (const auto& row : r.map_rows)
      if (row.held_out == held) d << num(row.joints_deg[j]) << ' ' << num(row.measured_hz) << '\n';
    if (std::none_of(r.map_rows.begin(), r.map_rows.end(), [&](const auto& row) { return row.held_out == held; }))
      d << "NaN NaN\n";
  }
  std::ostringstream p;
  p << "set terminal pngcairo noenhanced size 1100,520 font ',10'\nset grid\nset key outside right\n"
       "set xlabel 'joint "
    << j + 1 << " (deg)'\nset ylabel 'mode frequency (Hz)'\nplot ";
  for (std::size_t m = 0; m < modes; ++m)
    p << "DATA index 0 using 1:" << m + 2 << " with lines lw 2 lc rgb '#3367d6' title '"
      << (m == 0 ? "mapped along the path" : "") << "', ";
  p << "DATA index 1 using 1:2 with points pt 7 ps 1.4 lc rgb '#1d2430' title 'measured, in the map', "
       "DATA index 2 using 1:2 with points pt 6 ps 1.8 lw 2 lc rgb '#d0342c' title 'measured, held out'\n";
  return figure(
      dir, "path_modes", p.str(), d.str(),
      "The modes along the path: the map (lines) through the modes identified at the stops in it (filled), checked "
      "at the stops held out (open)");
}

// At each stop: the driving point's improvement measured on the cell and predicted on the map; the job's limit
// at its speed damped and open. Data: joint, measured %, predicted %, damped mm, open mm, the prediction's one
// sigma (points; drawn as its band of PathCommissionSettings::prediction_sigmas).
std::string stops_figure(const PathCommissionSettings& settings, const PathCommissionResult& r, const fs::path& dir) {
  if (std::none_of(r.stops.begin(), r.stops.end(), [](const PathStop& s) { return s.on_cell; })) return {};
  const std::size_t j = moving_joint(r.stops);
  std::ostringstream d;
  for (const auto& s : r.stops)
    d << num(s.joints_deg[j]) << ' ' << num(s.on_cell ? s.measured_improvement_pct : NAN) << ' '
      << num(s.predicted_improvement_pct) << ' ' << num(s.damped_limit_mm) << ' ' << num(s.open_limit_mm) << ' '
      << num(s.predicted_sigma_pct) << '\n';
  std::ostringstream p;
  // The keys above each panel: outside on the right they widen the panels apart and the joint axes disagree.
  p << "set terminal pngcairo noenhanced size 1100,760 font ',10'\nset multiplot layout 2,1\nset grid\n"
       "set key tmargin center horizontal\nset lmargin 11\nset offsets graph 0.04, graph 0.04, 0, 0\n"
       "set xlabel 'joint "
    << j + 1
    << " (deg)'\nset ylabel 'driving-point improvement (%)'\n"
       "plot DATA using 1:3:("
    << num(settings.prediction_sigmas)
    << "*$6) with yerrorbars pt 6 ps 2 lw 2 lc rgb '#3367d6' title 'predicted on the map (+/- "
    << num(settings.prediction_sigmas)
    << " sigma of its spread)', "
       "DATA using 1:2 with points pt 7 ps 1.3 lc rgb '#1d2430' title 'measured on the cell'\n"
       "set ylabel 'the job at its speed (mm)'\nset yrange [0:*]\n"
       "plot DATA using 1:4 with points pt 7 ps 1.5 lc rgb '#2e9e4f' title 'damped', "
       "DATA using 1:5 with points pt 4 ps 1.5 lw 2 lc rgb '#7a8494' title 'open loop'\nunset multiplot\n";
  return figure(
      dir, "path_stops", p.str(), d.str(),
      "At each stop: the improvement measured on the cell against the map's prediction (top); the job's limiting "
      "depth at its speed, damped and open loop (bottom)");
}

std::string stops_table(const PathCommissionSettings& s, const PathCommissionResult& r) {
  std::ostringstream h;
  h << "<h2>The stops</h2>\n<table><tr><th>stop</th><th>joints (deg)</th><th>map</th><th>actuator (Hz)</th><th>set</th>"
       "<th>improvement measured (%)</th><th>predicted, one sigma (%)</th><th>records</th><th>the job: damped / open "
       "(mm)</th>"
       "<th>open, the loop's plant (mm)</th><th>verdict</th></tr>\n";
  for (const auto& st : r.stops) {
    const bool held = st.improvement_held(s.improvement_tolerance_points, s.peak_tolerance, s.prediction_sigmas),
               cut = st.cut_not_worse();
    h << "<tr><td>" << esc(st.name) << "</td><td>" << esc(config::describe_pose(st.joints_deg)) << "</td><td>"
      << (st.held_out ? "held out" : "in it") << "</td><td>" << fmt("%.3f", st.actuator_hz) << "</td><td>"
      << esc(st.region) << fmt(", K %.0f", st.gain_ns_per_m) << "</td><td>"
      << (st.on_cell ? fmt("%.1f", st.measured_improvement_pct) : std::string("-")) << "</td><td>"
      << fmt("%.1f &plusmn; %.1f", st.predicted_improvement_pct, st.predicted_sigma_pct) << "</td><td>" << st.records
      << "</td><td>" << fmt("%.3f / %.3f", st.damped_limit_mm, st.open_limit_mm) << "</td><td>"
      << fmt("%.3f", st.loop_open_limit_mm) << "</td><td class=" << (held && cut ? "ok" : "bad") << ">"
      << (!st.on_cell ? "not measured on the cell"
          : !held     ? fmt("off by %.1f points, the damped peak %+.0f %%",
                            st.measured_improvement_pct - st.predicted_improvement_pct, 100.0 * st.peak_error())
          : !cut      ? std::string("the damper makes the cut worse")
                      : std::string("held"))
      << "</td></tr>\n";
  }
  h << "</table>\n<p>The improvement: the driving point's receptance peak, open over closed, minus one, from the "
       "emulator's "
       "impacts at each stop with the controller running against the same impacts on the robot standing there with the "
       "amplifier off; predicted by the set that runs there (the hand-over's hysteresis along the path) on the mapped "
       "model "
       "(discrete loop); allowed "
    << fmt("%.1f", s.improvement_tolerance_points) << " points, or the damped peak within "
    << fmt("%.0f", 100.0 * s.peak_tolerance) << " % of the predicted, or " << fmt("%.0f", s.prediction_sigmas)
    << " sigma of the prediction's own spread: each mapped mode's frequency, damping and participation on the map "
       "carries a sigma there (small at a stop in the map, larger between them), propagated to the improvement to "
       "first order. The job: its limiting depth at "
    << fmt("%.0f", r.job_rpm) << " rpm by " << esc(r.method)
    << "; the open loop over the model's modes, and over the loop's plant alone (its lowest "
       "modes, as the damped limit sees them): the damper is worse where the damped limit is below the latter.</p>\n";
  return h.str();
}

std::string map_table(const PathCommissionResult& r) {
  std::ostringstream h;
  h << "<h2>The map</h2>\n<p>The modes of " << esc(r.mapped_model_path)
    << " against those identified at each stop (at a "
       "stop held out of it, the map's check: the largest frequency error "
    << fmt("%.2f %%, %d mode(s) missed", r.held_out_worst_freq_error_pct, r.held_out_modes_missed)
    << "). The actuator identified at each stop spreads " << fmt("%.2f %%", r.actuator_spread_pct)
    << " in frequency.</p>\n"
    << "<table><tr><th>stop</th><th>role</th><th>measured (Hz)</th><th>mapped (Hz)</th><th>error (%)</th><th>sigma "
       "(%)</th>"
       "<th>stiffness error (%)</th><th>nearest stop in the map (deg)</th></tr>\n";
  for (const auto& row : r.map_rows)
    h << "<tr><td>" << esc(row.pose) << "</td><td>" << (row.held_out ? "held out" : "in the map") << "</td><td>"
      << fmt("%.3f", row.measured_hz) << "</td><td>" << fmt("%.3f", row.mapped_hz) << "</td><td>"
      << fmt("%+.2f", 100.0 * (row.mapped_hz / row.measured_hz - 1.0)) << "</td><td>" << fmt("%.2f", row.freq_sigma_pct)
      << "</td><td>" << fmt("%+.1f", 100.0 * (row.mapped_stiffness_n_per_m / row.measured_stiffness_n_per_m - 1.0))
      << "</td><td>" << fmt("%.1f", row.nearest_measured_deg) << "</td></tr>\n";
  h << "</table>\n";
  return h.str();
}

std::string tuned_table(const PathCommissionResult& r) {
  if (!r.tuned) return {};
  std::ostringstream h;
  h << "<h2>The controllers compared on the workspace "
       "map</h2>\n<table><tr><th>controller</th><th>regions</th><th>stable at every "
       "map pose</th><th>worst mode in the damping band (%)</th><th>worst driving point (%)</th><th>the job's smallest "
       "damped "
       "depth (mm)</th></tr>\n";
  for (std::size_t i = 0; i < r.tuned->scores.controllers.size(); ++i) {
    const tune::ControllerScore& c = r.tuned->scores.controllers[i];
    const std::size_t regions = i == 0 ? 1 : i == 1 ? r.tuned->scheduled.size() : 0;
    h << "<tr><td>" << esc(c.name) << (i == r.tuned->best ? " (chosen)" : "") << "</td><td>"
      << (i < 2 ? std::to_string(regions) : std::string("as configured")) << "</td><td>"
      << (c.stable_everywhere ? "yes" : "NO") << "</td><td>" << fmt("%+.1f", c.worst_mode_improvement_pct)
      << "</td><td>" << fmt("%+.1f", c.worst_improvement_pct) << "</td><td>"
      << (c.damped_min_mm ? fmt("%.4f", *c.damped_min_mm) : std::string("-")) << "</td></tr>\n";
  }
  h << "</table>\n";
  if (!r.lowered.empty()) {
    h << "<p>Never worse than no damper at the job's speed (tune/never_worse.hpp: each set checked along its region "
         "and at "
         "every map pose and stop inside it):";
    for (const auto& l : r.lowered) h << " " << esc(l) << ";";
    h << "</p>\n";
  }
  return h.str();
}

}  // namespace

json to_json(const PathCommissionResult& r) {
  json stops = json::array();
  for (const auto& s : r.stops)
    stops.push_back({{"name", s.name},
                     {"joints_deg", s.joints_deg},
                     {"held_out", s.held_out},
                     {"actuator_hz", s.actuator_hz},
                     {"region", s.region},
                     {"gain_ns_per_m", s.gain_ns_per_m},
                     {"predicted_improvement_pct", s.predicted_improvement_pct},
                     {"predicted_improvement_sigma_pct", s.predicted_sigma_pct},
                     {"measured_improvement_pct", s.on_cell ? json(s.measured_improvement_pct) : json(nullptr)},
                     {"damped_peak_error_pct", s.on_cell ? json(100.0 * s.peak_error()) : json(nullptr)},
                     {"records", s.records},
                     {"coherence_min", s.coherence_min},
                     {"open_limit_mm", s.open_limit_mm},
                     {"loop_open_limit_mm", s.loop_open_limit_mm},
                     {"damped_limit_mm", s.damped_limit_mm}});
  json rows = json::array();
  for (const auto& row : r.map_rows)
    rows.push_back({{"pose", row.pose},
                    {"joints_deg", row.joints_deg},
                    {"held_out", row.held_out},
                    {"measured_hz", row.measured_hz},
                    {"mapped_hz", std::isfinite(row.mapped_hz) ? json(row.mapped_hz) : json(nullptr)},
                    {"freq_sigma_pct", row.freq_sigma_pct},
                    {"measured_stiffness_n_per_m", row.measured_stiffness_n_per_m},
                    {"mapped_stiffness_n_per_m", row.mapped_stiffness_n_per_m}});
  json times = json::array();
  for (const auto& t : r.times) times.push_back({{"stage", to_string(t.stage)}, {"wall_s", t.wall_s}});
  json out = {{"outcome", r.outcome == Outcome::kVerified ? "verified" : "not verified"},
              {"stage", to_string(r.stage)},
              {"reason", r.reason},
              {"wall_s", r.wall_s},
              {"times", times},
              {"stops", stops},
              {"map", rows},
              {"held_out_worst_freq_error_pct", r.held_out_worst_freq_error_pct},
              {"held_out_modes_missed", r.held_out_modes_missed},
              {"actuator_spread_pct", r.actuator_spread_pct},
              {"mapped_model", r.mapped_model_path},
              {"chosen", r.chosen},
              {"gains_lowered", r.lowered},
              {"job_rpm", r.job_rpm},
              {"method", r.method},
              {"trip", r.trip},
              {"pose_out_of_map", r.pose_out_of_map},
              {"saturated_ticks", r.saturated_ticks},
              {"configuration", r.configuration_path}};
  return out;
}

std::string write_path_report(const PathCommissionSettings& s, const PathCommissionResult& r,
                              const std::string& html_path) {
  const fs::path dir = fs::path(html_path).parent_path();
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>robodamp commission along the path: "
    << esc(s.config_path)
    << "</"
       "title>\n<style>body{font-family:sans-serif;max-width:1250px;margin:auto;padding:1em}table{border-collapse:"
       "collapse;"
       "margin:0.5em 0}td,th{border:1px solid #bbb;padding:3px "
       "8px;text-align:right}th{background:#eee}td:first-child{text-align:left}"
       ".ok{color:#1e8449}.bad{color:#c0392b;font-weight:bold}.banner{padding:0.6em;font-size:1.2em;border-radius:4px}"
       ".pass{background:#d5f5e3}.fail{background:#fadbd8}img{max-width:100%}code{background:#f4f4f4}</style></"
       "head><body>\n"
    << "<h1>robodamp commission along the path</h1>\n<p>Cell <code>" << esc(s.config_path) << "</code>, job <code>"
    << esc(s.job_path) << "</code>; robodamp " << rt::version() << " (" << rt::git_commit() << ").<br>Command: <code>"
    << esc(s.command_line) << "</code></p>\n";
  if (r.outcome == Outcome::kVerified)
    h << "<p class=\"banner pass\">VERIFIED at every stop: " << esc(r.configuration_path) << " written (the "
      << esc(r.chosen) << " controller).</p>\n";
  else
    h << "<p class=\"banner fail\">NOT VERIFIED: stopped at the " << to_string(r.stage) << " stage: " << esc(r.reason)
      << ". Nothing written as configuration.yaml.</p>\n";
  h << "<table><tr><th>stage</th><th>wall time (s)</th></tr>\n";
  for (const auto& t : r.times)
    h << "<tr><td>" << to_string(t.stage) << (t.reused ? " (reused from the directory)" : "") << "</td><td>"
      << fmt("%.1f", t.wall_s) << "</td></tr>\n";
  h << "<tr><td>total</td><td>" << fmt("%.1f", r.wall_s) << "</td></tr></table>\n";
  try {
    h << stops_table(s, r) << stops_figure(s, r, dir / "plots") << map_table(r) << modes_figure(s, r, dir / "plots")
      << tuned_table(r);
  } catch (const std::exception& e) {
    h << "<p class=bad>" << esc(e.what()) << "</p>\n";
  }
  h << "</body></html>\n";
  std::ofstream out(html_path);
  out << h.str();
  std::ofstream(dir / "report.json") << to_json(r).dump(2) << '\n';
  if (!out) return "cannot write " + html_path;
  return {};
}

}  // namespace robodamp::commission
