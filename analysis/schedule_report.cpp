#include "analysis/schedule_report.hpp"

#include <cmath>
#include <sstream>
#include <vector>

#include "analysis/loop_model.hpp"
#include "analysis/notch_speed_map.hpp"
#include "analysis/pose_schedule.hpp"
#include "analysis/speed_schedule_check.hpp"
#include "fields/json.hpp"
#include "fields/printf.hpp"

namespace robodamp::analysis {

namespace {

using fields::number_or_null;
using fields::number_text;
using fields::printf_string;
using nlohmann::json;

// The speed map as JSON: every speed with the notches' phase at each mode, and the refused ranges.
json speed_map_json(const config::Config& cfg, const NotchSpeedMap& map) {
  json points = json::array();
  for (const auto& p : map.points)
    points.push_back({{"rpm", p.rpm},
                      {"stable", p.stable},
                      {"refused", p.refused},
                      {"reason", p.reason},
                      {"notch_phase_deg", p.notch_phase_deg}});
  json refused = json::array();
  for (const auto& [lo, hi] : map.refused_rpm) refused.push_back({{"from_rpm", lo}, {"to_rpm", hi}});
  return {{"config", cfg.source},
          {"teeth", cfg.spindle.teeth},
          {"mode_hz", map.points.empty() ? json::array() : json(map.points.front().mode_hz)},
          {"points", points},
          {"refused", refused}};
}

}  // namespace

TextReport notch_speed_map_report(const config::Config& cfg) {
  const NotchSpeedMap map = notch_speed_map(cfg);
  TextReport r{speed_map_json(cfg, map), {}};
  if (map.points.empty()) {
    r.text = "no controller.harmonic_notch configured: nothing to sweep\n";
    return r;
  }
  std::string& t = r.text;
  t += printf_string("harmonic notches across %.0f-%.0f rpm (%zu speeds, %d teeth):\n", map.points.front().rpm,
                     map.points.back().rpm, map.points.size(), cfg.spindle.teeth);
  for (std::size_t k = 0; k < map.points.front().mode_hz.size(); ++k) {
    double worst = 0.0, at = 0.0;
    for (const auto& p : map.points)
      if (std::abs(p.notch_phase_deg[k]) > std::abs(worst)) worst = p.notch_phase_deg[k], at = p.rpm;
    t += printf_string("  %.2f Hz mode: the notches cost at most %+.1f deg (at %.0f rpm)\n",
                       map.points.front().mode_hz[k], worst, at);
  }
  if (map.refused_rpm.empty()) t += "  no speed refused\n";
  for (const auto& [lo, hi] : map.refused_rpm) {
    std::string why;
    for (const auto& p : map.points)
      if (p.refused && p.rpm >= lo && p.rpm <= hi) {
        why = p.reason;
        break;
      }
    t += printf_string("  refused %.0f-%.0f rpm: %s; the notches park there\n", lo, hi, why.c_str());
  }
  return r;
}

namespace {

// The regions' table and each region's worst mode in the damping band.
std::string pose_schedule_text(const config::Config& cfg, const PoseScheduleAnalysis& ps, const json& regions) {
  const config::PoseScheduleConfig& sched = *cfg.pose_schedule;
  std::string t = printf_string("pose schedule of %s: robot model %s, actuator along %s\n", cfg.source.c_str(),
                                ps.model.source.c_str(), sched.axis ? "y" : "x");
  t += printf_string("%-12s %-26s %-18s %9s %4s %9s %11s %9s %9s %8s\n", "region", "centre (deg)", "dominant (Hz)",
                     "match Hz", "pol", "K N s/m", "K_max N s/m", "GM dB", "PM deg", "impr %");
  for (const auto& r : regions) {
    const std::string centre = config::describe_pose(r["centre_deg"].get<std::vector<double>>());
    const std::string dom =
        printf_string("%.2f-%.2f", r["dominant_min_hz"].get<double>(), r["dominant_max_hz"].get<double>());
    t += printf_string("%-12s %-26s %-18s %9.2f %+4d %9.0f %11.0f %9s %9s %8.1f\n",
                       r["name"].get<std::string>().c_str(), centre.c_str(), dom.c_str(),
                       r["dominant_hz"].get<double>(), r["polarity"].get<int>(), r["gain_ns_per_m"].get<double>(),
                       r["k_max_ns_per_m"].get<double>(), number_text(r["centre_gain_margin_db"], "%.1f").c_str(),
                       number_text(r["centre_phase_margin_deg"], "%.1f").c_str(),
                       r["improvement_centre_pct"].get<double>());
  }
  t += printf_string("K_max is the smallest over each region's %d^%zu grid; margins and improvement at its centre\n",
                     sched.grid_points, sched.joints());
  t += printf_string(
      "the worst mode in the damping band %g-%g Hz over each region's grid (the smallest improvement of a robot mode's "
      "peak, %s within +-10 %%):\n",
      sched.damping_band_min_hz, sched.damping_band_max_hz,
      cfg.robot.frfs.empty() ? "-" : cfg.robot.frfs.front().name.c_str());
  for (const auto& r : regions) {
    const double w = r["worst_mode_improvement_pct"];
    t += printf_string("  %-12s %+7.1f %% at %.2f Hz at %s%s", r["name"].get<std::string>().c_str(), w,
                       r["worst_mode_hz"].get<double>(),
                       config::describe_pose(r["worst_mode_pose_deg"].get<std::vector<double>>()).c_str(),
                       w < 0.0 ? ": worse than open loop there" : "");
    if (!r["outside_band_pct"].is_null())
      t += printf_string("; outside the band %+.1f %% at %.2f Hz", r["outside_band_pct"].get<double>(),
                         r["outside_band_hz"].get<double>());
    t += "\n";
  }
  return t;
}

}  // namespace

TextReport pose_schedule_report(const config::Config& cfg) {
  const PoseScheduleAnalysis ps = analyse_pose_schedule(cfg);
  json regions = json::array();
  for (const auto& r : ps.regions) {
    const LoopModel centre(r.config);
    const AnalysisResult a = analyse(centre, r.gain_ns_per_m, r.polarity);
    regions.push_back({{"name", r.name},
                       {"centre_deg", r.centre_deg},
                       {"dominant_hz", r.dominant_hz},
                       {"dominant_min_hz", r.dominant_min_hz},
                       {"dominant_max_hz", r.dominant_max_hz},
                       {"grid_poses", r.grid_poses},
                       {"gain_ns_per_m", r.gain_ns_per_m},
                       {"polarity", r.polarity},
                       {"k_max_ns_per_m", r.k_max_ns_per_m},
                       {"k_max_pose_deg", r.k_max_pose_deg},
                       {"centre_gain_margin_db", number_or_null(a.margins.gain_margin_db)},
                       {"centre_phase_margin_deg", number_or_null(a.margins.phase_margin_deg)},
                       {"improvement_centre_pct", r.improvement_centre_pct},
                       {"worst_mode_improvement_pct", r.worst_mode_improvement_pct},
                       {"worst_mode_hz", r.worst_mode_hz},
                       {"worst_mode_pose_deg", r.worst_mode_pose_deg},
                       {"outside_band_pct", r.outside_band_pct ? json(*r.outside_band_pct) : json(nullptr)},
                       {"outside_band_hz", r.outside_band_hz ? json(*r.outside_band_hz) : json(nullptr)}});
  }
  const config::PoseScheduleConfig& sched = *cfg.pose_schedule;
  TextReport out;
  out.json = {{"config", cfg.source},
              {"model", ps.model.source},
              {"axis", sched.axis ? "y" : "x"},
              {"damping_band_hz", {sched.damping_band_min_hz, sched.damping_band_max_hz}},
              {"regions", regions}};
  out.text = pose_schedule_text(cfg, ps, regions);
  return out;
}

std::string speed_schedule_section(const config::Config& cfg, json& report) {
  if (!cfg.controller.speed_schedule) return {};
  std::ostringstream os;
  const auto loops = check_speed_schedule(cfg);
  os << "  speed schedule: " << cfg.controller.speed_schedule->bands.size()
     << " bands (robodamp schedule; K = 0 in a band "
     << "where the damper is worse than none); each controller and K they run, as a loop:\n";
  json j = json::array();
  for (const auto& l : loops) {
    char line[300];
    std::snprintf(
        line, sizeof line, "    controller %zu at K %6.0f N s/m (%zu band%s from %.0f rpm): %s, GM %s dB, %s\n",
        l.controller, l.gain_ns_per_m, l.bands, l.bands == 1 ? "" : "s", l.rpm_from, l.stable ? "stable" : "UNSTABLE",
        l.margins.gain_margin_db ? number_text(json(*l.margins.gain_margin_db), "%.1f").c_str() : "-",
        l.margins.phase_margin_deg ? ("PM " + number_text(json(*l.margins.phase_margin_deg), "%.1f") + " deg").c_str()
                                   : "no gain crossover");
    os << line;
    for (const auto& w : l.warnings) os << "      WARNING: " << w << "\n";
    for (const auto& n : l.notes) os << "      note: " << n << "\n";
    j.push_back({{"controller", l.controller},
                 {"gain_ns_per_m", l.gain_ns_per_m},
                 {"bands", l.bands},
                 {"stable", l.stable},
                 {"gain_margin_db", number_or_null(l.margins.gain_margin_db)},
                 {"phase_margin_deg", number_or_null(l.margins.phase_margin_deg)},
                 {"warnings", l.warnings},
                 {"notes", l.notes}});
  }
  report["speed_schedule"] = j;
  return os.str();
}

}  // namespace robodamp::analysis
