#include "tune/speed_schedule_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace robodamp::tune {

namespace {

using nlohmann::json;

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

std::string pct(double ratio) { return fmt("%+.1f %%", 100.0 * (ratio - 1.0)); }

std::string controller_name(const SpeedSchedule& s, std::size_t c) {
  return c == 0 ? "0 (this configuration's)" : std::to_string(c) + " (" + s.controllers[c].file + ")";
}

std::string controllers_text(const SpeedSchedule& s) {
  std::ostringstream o;
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    const auto& k = s.controllers[c];
    o << "  controller " << controller_name(s, c) << ": K_max "
      << (k.k_max_ns_per_m ? fmt("%.0f", *k.k_max_ns_per_m) : std::string("none below the gain limit"))
      << " N s/m; K tried " << fmt("%.0f", k.gains.empty() ? 0.0 : k.gains.front()) << " to "
      << fmt("%.0f", k.top_gain_ns_per_m) << " N s/m (the top set by " << k.top_gain_reason << ")\n";
  }
  return o.str();
}

// One row of the verdict's table: the label and three cells, each padded to its column.
std::string row(const std::string& label, const std::string& open, const std::string& fixed, const std::string& sched) {
  char line[400];
  std::snprintf(line, sizeof line, "    %-30s %-20s %-28s %s\n", label.c_str(), open.c_str(), fixed.c_str(),
                sched.c_str());
  return line;
}

// The verdict in the machinist's terms: where the damper as configured is worse than none, and the schedule.
std::string verdict_text(const SpeedSchedule& s) {
  const ScheduleSummary& m = s.summary;
  const ScheduleSettings& st = s.settings;
  std::ostringstream o;
  o << "  what the damper does for this job (" << s.method << ", every depth; " << m.speeds
    << " speeds: " << m.grid_speeds << " chosen on, the rest checks between):\n";
  o << row("", "open loop", "as configured", "scheduled by speed");
  if (m.job_rpm > 0.0)
    o << row(fmt("at the job's %.1f rpm", m.job_rpm), fmt("%.3f mm", m.job_open_mm),
             fmt("%.3f mm (", m.job_fixed_mm) + pct(m.job_fixed_mm / m.job_open_mm) + ")",
             fmt("%.3f mm (", m.job_scheduled_mm) + pct(m.job_scheduled_mm / m.job_open_mm) + ")");
  o << row(
      "minimum", fmt("%.3f mm at %.0f rpm", m.open_min_mm, m.open_min_rpm),
      fmt("%.3f mm at %.0f rpm (x%.2f)", m.fixed_min_mm, m.fixed_min_rpm, m.fixed_min_mm / m.open_min_mm),
      fmt("%.3f mm at %.0f rpm (x%.2f)", m.scheduled_min_mm, m.scheduled_min_rpm, m.scheduled_min_mm / m.open_min_mm));
  o << row("mean over the speeds", "x1", fmt("x%.3f", m.fixed_mean_ratio), fmt("x%.3f", m.scheduled_mean_ratio));
  o << row(fmt("worse than open (> %.1f %%)", st.worse_tolerance_pct), "",
           fmt("%.0f %% of the speeds", 100.0 * m.fixed_worse_share),
           fmt("%.1f %% of the speeds", 100.0 * m.scheduled_worse_share));
  o << row("the worst, x open loop", "", fmt("x%.2f at %.0f rpm", m.fixed_worst_ratio, m.fixed_worst_rpm),
           fmt("x%.3f at %.0f rpm", m.scheduled_worst_ratio, m.scheduled_worst_rpm));
  o << fmt("  the schedule is deeper than the open loop (by > %.0f %%) at %.0f %% of the speeds and runs K = 0 (the "
           "open loop) "
           "at the rest",
           st.gain_min_pct, 100.0 * m.scheduled_better_share)
    << (m.scheduled_worse_share > 0.0 ? fmt("; it is WORSE than the open loop at %.1f %% of them (the worst x%.3f): "
                                            "see the speeds below",
                                            100.0 * m.scheduled_worse_share, m.scheduled_worst_ratio)
                                      : std::string("; never worse than the open loop at the speeds checked"))
    << "\n";
  if (m.fixed_worse_share > 0.0)
    o << fmt("  as configured, the damper LOWERS the limit at %.0f %% of the speeds (down to x%.2f at %.0f rpm)",
             100.0 * m.fixed_worse_share, m.fixed_worst_ratio, m.fixed_worst_rpm)
      << (m.job_rpm > 0.0 && m.job_fixed_mm < m.job_open_mm
              ? fmt(", the job's %.1f rpm among them (%.3f mm instead of %.3f mm)", m.job_rpm, m.job_fixed_mm,
                    m.job_open_mm)
              : std::string())
      << ": the schedule switches it off or changes it there\n";
  return o.str();
}

}  // namespace

std::string schedule_text(const SpeedSchedule& s, const std::string& cell, const std::string& job) {
  std::ostringstream o;
  o << "robodamp schedule: " << cell << " on " << job << "\n" << controllers_text(s) << verdict_text(s);
  o << "  every damped limit is capped where the cut's forced vibration drives the actuator to its force limit: "
    << s.capped_limits << " of " << s.damped_limits << " were\n";
  o << "  every damped limit the bands run is checked in time (the real Controller, a cut at 0.95 x the limit): "
    << s.lowered_in_time << " of " << s.limits_in_time
    << " chattered: there another candidate runs, or the same at its "
    << "limit in time (bands with a depth_limit_mm, which the cell's limits honour: " << s.limited_bands() << ")\n";
  for (const auto& l : s.lowered)
    o << fmt("    at %.1f rpm, controller ", l.rpm) << controller_name(s, s.candidates[l.candidate].controller)
      << fmt(" at K %.0f N s/m: %.3f mm by the accurate method, %.3f mm in time",
             s.candidates[l.candidate].gain_ns_per_m, l.accurate_mm, l.time_mm)
      << (l.kept ? "; runs there at its limit in time" : "; another candidate runs there") << "\n";
  o << "  bands (" << s.bands.size() << "; " << s.refined_speeds
    << " speeds refined where a check found a band worse):\n";
  for (const auto& b : s.bands)
    o << fmt("    %8.1f - %8.1f rpm: ", b.rpm_min, b.rpm_max)
      << (b.gain_ns_per_m == 0.0 ? std::string("K 0 (the open loop)")
                                 : "controller " + controller_name(s, static_cast<std::size_t>(b.controller)) +
                                       fmt(" at K %.0f N s/m", b.gain_ns_per_m))
      << (b.depth_limit_mm ? fmt(", at most %.3f mm (its limit in time)", *b.depth_limit_mm) : std::string()) << "\n";
  const double tol = 1.0 - 0.01 * s.settings.worse_tolerance_pct;
  for (const auto& p : s.speeds)
    if (p.scheduled_mm < p.open_mm * tol)
      o << fmt("  WORSE at %.1f rpm: %.3f mm scheduled, %.3f mm open loop\n", p.rpm, p.scheduled_mm, p.open_mm);
  for (const auto& n : s.notes) o << "  note: " << n << "\n";
  return o.str();
}

json schedule_json(const SpeedSchedule& s) {
  const ScheduleSummary& m = s.summary;
  json controllers = json::array(), bands = json::array(), speeds = json::array();
  for (const auto& c : s.controllers)
    controllers.push_back({{"file", c.file},
                           {"polarity", c.polarity},
                           {"k_max_ns_per_m", c.k_max_ns_per_m ? json(*c.k_max_ns_per_m) : json(nullptr)},
                           {"top_gain_ns_per_m", c.top_gain_ns_per_m},
                           {"top_gain_reason", c.top_gain_reason},
                           {"gains_ns_per_m", c.gains}});
  for (const auto& b : s.bands)
    bands.push_back({{"rpm_min", b.rpm_min},
                     {"rpm_max", b.rpm_max},
                     {"controller", b.controller},
                     {"gain_ns_per_m", b.gain_ns_per_m},
                     {"depth_limit_mm", b.depth_limit_mm ? json(*b.depth_limit_mm) : json(nullptr)}});
  for (const auto& p : s.speeds)
    speeds.push_back({{"rpm", p.rpm},
                      {"grid", p.grid},
                      {"open_mm", p.open_mm},
                      {"fixed_mm", p.fixed_mm},
                      {"scheduled_mm", p.scheduled_mm},
                      {"band", p.band},
                      {"candidate", p.candidate}});
  return {{"method", s.method},
          {"settings",
           {{"gain_margin_min_db", s.settings.gain_margin_min_db},
            {"phase_margin_min_deg", s.settings.phase_margin_min_deg},
            {"delay_margin_min_ms", s.settings.delay_margin_min_ms},
            {"gain_min_pct", s.settings.gain_min_pct},
            {"worse_tolerance_pct", s.settings.worse_tolerance_pct}}},
          {"controllers", controllers},
          {"bands", bands},
          {"speeds", speeds},
          {"refined_speeds", s.refined_speeds},
          {"damped_limits", s.damped_limits},
          {"capped_limits", s.capped_limits},
          {"limits_in_time", s.limits_in_time},
          {"lowered_in_time", s.lowered_in_time},
          {"summary",
           {{"speeds", m.speeds},
            {"grid_speeds", m.grid_speeds},
            {"open_min_mm", m.open_min_mm},
            {"open_min_rpm", m.open_min_rpm},
            {"fixed_min_mm", m.fixed_min_mm},
            {"fixed_min_rpm", m.fixed_min_rpm},
            {"scheduled_min_mm", m.scheduled_min_mm},
            {"scheduled_min_rpm", m.scheduled_min_rpm},
            {"fixed_mean_ratio", m.fixed_mean_ratio},
            {"scheduled_mean_ratio", m.scheduled_mean_ratio},
            {"fixed_worse_share", m.fixed_worse_share},
            {"scheduled_worse_share", m.scheduled_worse_share},
            {"fixed_worst_ratio", m.fixed_worst_ratio},
            {"fixed_worst_rpm", m.fixed_worst_rpm},
            {"scheduled_worst_ratio", m.scheduled_worst_ratio},
            {"scheduled_worst_rpm", m.scheduled_worst_rpm},
            {"scheduled_better_share", m.scheduled_better_share},
            {"job_rpm", m.job_rpm},
            {"job_open_mm", m.job_open_mm},
            {"job_fixed_mm", m.job_fixed_mm},
            {"job_scheduled_mm", m.job_scheduled_mm}}},
          {"notes", s.notes}};
}

std::string schedule_header(const SpeedSchedule& s) {
  const ScheduleSummary& m = s.summary;
  std::ostringstream o;
  o << "# The speed schedule (controller.speed_schedule) was verified with " << s.method << " at " << m.speeds
    << " speeds, each damped limit checked in time (a cut at 0.95 x it, the real Controller; " << s.lowered_in_time
    << " of " << s.limits_in_time << " chattered: another candidate runs there, or the same at its limit "
    << "in time; bands with depth_limit_mm: " << s.limited_bands() << "):\n"
    << fmt("#   minimum %.3f mm at %.0f rpm (open loop %.3f mm, as configured %.3f mm); ", m.scheduled_min_mm,
           m.scheduled_min_rpm, m.open_min_mm, m.fixed_min_mm)
    << fmt("mean x%.3f the open loop (as configured x%.3f);\n", m.scheduled_mean_ratio, m.fixed_mean_ratio)
    << fmt("#   worse than the open loop by > %.1f %% at %.1f %% of the speeds (worst x%.3f",
           s.settings.worse_tolerance_pct, 100.0 * m.scheduled_worse_share, m.scheduled_worst_ratio)
    << fmt(" at %.0f rpm); as configured at %.0f %% (worst x%.2f)", m.scheduled_worst_rpm, 100.0 * m.fixed_worse_share,
           m.fixed_worst_ratio);
  if (m.job_rpm > 0.0)
    o << fmt(";\n#   at the job's %.0f rpm %.3f mm (open loop %.3f mm, as configured %.3f mm)", m.job_rpm,
             m.job_scheduled_mm, m.job_open_mm, m.job_fixed_mm);
  o << ".\n";
  return o.str();
}

std::pair<std::string, std::string> schedule_plot(const SpeedSchedule& s, const std::string& title) {
  std::ostringstream data;
  // Columns: rpm, open, as configured, scheduled, the band's depth_limit_mm (-1: none).
  for (const auto& p : s.speeds) {
    const auto& cap = p.band < s.bands.size() ? s.bands[p.band].depth_limit_mm : std::nullopt;
    data << fmt("%.10g %.10g %.10g %.10g", p.rpm, p.open_mm, p.fixed_mm, p.scheduled_mm)
         << fmt(" %.10g\n", cap ? *cap : -1.0);
  }
  // A logarithmic depth axis: the limits span two decades (the minima near the modes' lobes, the pockets between).
  double y_min = std::numeric_limits<double>::infinity(), y_max = 0.0;
  for (const auto& p : s.speeds) {
    for (const double v : {p.open_mm, p.fixed_mm, p.scheduled_mm})
      if (std::isfinite(v) && v > 0.0) y_min = std::min(y_min, v);
    if (std::isfinite(p.scheduled_mm)) y_max = std::max(y_max, p.scheduled_mm);
  }
  y_min = 0.8 * y_min;
  y_max = std::min(1.25 * y_max, 100.0 * y_min);
  std::ostringstream g;
  g << "set title '" << title << "' noenhanced\nset grid xtics ytics mytics\nset xlabel 'spindle speed (rpm)'\n"
    << "set ylabel 'limiting axial depth (mm, logarithmic)'\nset logscale y\nset key bottom right opaque box\n"
    << "set ytics ('0.05' 0.05, '0.1' 0.1, '0.2' 0.2, '0.5' 0.5, '1' 1, '2' 2, '5' 5, '10' 10, '20' 20, '50' 50, '100' "
       "100)\n"
    << "set yrange [" << y_min << ":" << y_max << "]\n"
    << "plot DATA u 1:2 w l lw 2 lc rgb '#7f8c8d' t 'open loop (SDM)', "
    << "DATA u 1:3 w l lw 1.5 lc rgb '#e67e22' t 'as configured (sampled-loop SDM)', "
    << "DATA u 1:4 w l lw 2.5 lc rgb '#27ae60' t 'scheduled by speed (sampled-loop SDM, each limit checked in time)', "
    << "DATA u 1:($5 > 0 ? $4 : 1/0) w p pt 7 ps 1.3 lc rgb '#c0392b' t 'a band limited to its depth in time "
       "(depth_limit_mm)'\n";
  return {data.str(), g.str()};
}

}  // namespace robodamp::tune
