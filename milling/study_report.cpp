#include "milling/study_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "config/robot_model_config.hpp"
#include "fields/json.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/chatter.hpp"
#include "milling/live_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/scheduled_lobes.hpp"
#include "milling/sle.hpp"
#include "milling/studies.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::milling {

using nlohmann::json;

namespace {

// What the zero-order method's depths are: a fast preview, never a promise (docs/milling.md).
constexpr const char* kPreview = kZeroOrderPreview;

using fields::finite_or_null;

config::StructureConfig selected(const config::MillingConfig& cfg, const StudyOptions& o) {
  return selected_structure(cfg, o.structure, o.controller_path);
}

template <typename T>
json optional_json(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

// One lobe study (open or damped, milling/studies.hpp) as the report's JSON.
json lobes_json(const LobeStudy& s, int teeth) {
  json j;
  j["structure"] = s.structure;
  j["closed_loop"] = s.closed_loop;
  j["method"] = s.method;
  if (s.accurate) j["steps_per_period"] = s.steps_per_period;
  j["frequency_points"] = s.frequency_points;
  j["curve"] = json::array();
  for (const auto& p : s.curve) {
    json c = {{"rpm", p.rpm}, {"b_lim_mm", finite_or_null(p.b_lim_mm)}, {"chatter_hz", optional_json(p.chatter_hz)}};
    if (s.accurate)
      c["type"] = *p.type;
    else
      c["lobe"] = *p.lobe;
    j["curve"].push_back(c);
  }
  j["min_b_lim_mm"] = finite_or_null(s.min_b_lim_mm);
  j["min_rpm"] = s.min_rpm;
  j["min_chatter_hz"] = s.min_chatter_hz;
  j["at_rpm"] = json::array();
  for (const auto& a : s.at_rpm) {
    json r = {{"rpm", a.rpm},
              {"b_lim_mm", finite_or_null(a.b_lim_mm)},
              {"b_lim_lobes_mm", optional_json(a.b_lim_lobes_mm)},
              {"chatter_hz", optional_json(a.chatter_hz)}};
    if (a.chatter_hz) r["chatter_family_hz"] = chatter_family_hz(*a.chatter_hz, a.rpm * teeth / 60.0);
    if (s.accurate)
      r["requested_rpm"] = *a.requested_rpm, r["type"] = *a.type;
    else
      r["lobe"] = optional_json(a.lobe);
    j["at_rpm"].push_back(r);
  }
  j["diagram_ms"] = s.diagram_ms;
  j["notes"] = s.notes;
  return j;
}

// The study by the requested method; the accurate one's progress on stderr (a many-mode open loop takes
// minutes).
json lobes_json(const Structure& structure, const config::MillingConfig& cfg, const std::vector<double>& rpms,
                const std::string& method, const StudyProgress& progress) {
  if (method != "sdm") return lobes_json(zero_order_lobe_study(structure, cfg, rpms), cfg.tool.teeth);
  return lobes_json(accurate_lobe_study(structure, cfg, rpms,
                                        [&](const std::string& name, std::size_t done, std::size_t of, double s) {
                                          if (progress && (done % 20 == 0 || done == of)) {
                                            std::ostringstream os;
                                            os << "[lobes " << name << "] " << done << "/" << of << " speeds, " << s
                                               << " s\n";
                                            progress(os.str());
                                          }
                                        }),
                    cfg.tool.teeth);
}

double pct_change(const json& open, const json& damped) {
  if (open.is_null() || damped.is_null()) return NAN;
  return (damped.get<double>() / open.get<double>() - 1.0) * 100.0;
}

using fields::number_text;

std::string tool_text(const config::MillingConfig& c) {
  std::ostringstream os;
  os << c.tool.diameter_mm << " mm " << c.tool.teeth << "-tooth " << to_string(c.tool.kind) << ", " << c.cut.radial_mm
     << " mm radial " << to_string(c.cut.mode) << " milling, " << c.material.name;
  return os.str();
}

// One SLE study (open or damped, milling/studies.hpp) as the report's JSON.
json sle_json(const SleStudy& s) {
  json j;
  j["structure"] = s.structure;
  j["closed_loop"] = s.closed_loop;
  j["map"] = json::array();
  for (const auto& p : s.map)
    j["map"].push_back({{"rpm", p.rpm},
                        {"sle_um", p.sle_um},
                        {"sle_min_um", p.sle_min_um},
                        {"sle_max_um", p.sle_max_um},
                        {"b_lim_preview_mm", finite_or_null(p.b_lim_preview_mm)},
                        {"stable", p.stable},
                        {"stability_method", p.stability_method}});
  j["map_unstable_points"] = s.map_unstable_points;
  j["stability_method"] = s.stability_method;  // the map's and the conditions' stable flags (docs/milling.md)
  j["map_preview_points"] = s.map_preview_points;
  j["conditions"] = json::array();
  for (const auto& c : s.conditions)
    j["conditions"].push_back({{"name", c.name},
                               {"rpm", c.rpm},
                               {"axial_mm", c.axial_mm},
                               {"radial_mm", c.radial_mm},
                               {"ft_mm", c.ft_mm},
                               {"surface_normal", to_string(c.surface_normal)},
                               {"sle_um", c.sle_um},
                               {"sle_dynamic_um", c.sle_dynamic_um},
                               {"path_offset_um", c.path_offset_um},
                               {"sle_min_um", c.sle_min_um},
                               {"sle_max_um", c.sle_max_um},
                               {"mean_normal_force_n", c.mean_normal_force_n},
                               {"compensated_radial_mm", c.compensated_radial_mm},
                               {"compensation_residual_um", c.compensation_residual_um},
                               {"compensation_iterations", c.compensation_iterations},
                               {"compensation_converged", c.compensation_converged},
                               {"stable", c.stable},
                               {"stability_method", c.stability_method}});
  j["notes"] = s.notes;
  return j;
}

}  // namespace

config::StructureConfig selected_structure(const config::MillingConfig& cfg, const std::string& structure,
                                           const std::string& controller_path) {
  const std::string name = structure.empty() ? cfg.structure : structure;
  if (const auto* s = cfg.find_structure(name)) {
    config::StructureConfig out = *s;
    if (!controller_path.empty())
      for (auto& part : out.parts)
        if (part.controller) part.controller->config_path = controller_path;
    return out;
  }
  std::string known;
  for (const auto& s : cfg.structures) known += (known.empty() ? "" : ", ") + s.name;
  throw config::ConfigError(
      {config::Problem{cfg.source, {}, "--structure", "= '" + name + "' is not one of: " + known}});
}

json lobes_report(const config::MillingConfig& cfg, const StudyOptions& o, const StudyProgress& progress) {
  const auto sc = selected(cfg, o);
  std::vector<double> rpms = o.rpm;
  rpms.push_back(cfg.cut.spindle_rpm);
  const Structure open(sc, false);
  if (o.damped && !open.has_controller())
    throw config::ConfigError({config::Problem{
        cfg.source, {}, "structures." + sc.name, "--damped needs a part with a controller (a damping configuration)"}});
  json r = lobes_json(open, cfg, rpms, o.method, progress);
  r["config"] = cfg.source;
  r["tool"] = tool_text(cfg);
  r["spindle_rpm"] = cfg.cut.spindle_rpm;
  if (cfg.cut.mode == config::MillingMode::kUp)
    r["notes"].push_back(
        "up milling starts each chip at zero thickness: a start-up transient can take the tool out of "
        "the cut and chatter below these linear limits (docs/milling.md); `robodamp cut --critical` "
        "simulates it");
  if (o.damped) {
    const Structure closed(sc, true);
    r["damped"] = lobes_json(closed, cfg, rpms, o.method, progress);
    r["gain"] = {{"min_b_lim_change_pct", finite_or_null(pct_change(r["min_b_lim_mm"], r["damped"]["min_b_lim_mm"]))},
                 {"at_spindle_rpm", cfg.cut.spindle_rpm},
                 {"at_spindle_change_pct", finite_or_null(pct_change(r["at_rpm"].back()["b_lim_mm"],
                                                                     r["damped"]["at_rpm"].back()["b_lim_mm"]))}};
    // The damping configuration's speed schedule, beside the fixed gain: each speed with its band's controller.
    if (o.method == "sdm")
      if (const auto sl = scheduled_lobe_study(sc, cfg, rpms, [&](std::size_t done, std::size_t of) {
            if (progress && (done % 40 == 0 || done == of))
              progress("[lobes speed schedule] " + std::to_string(done) + "/" + std::to_string(of) + "\n");
          })) {
        json j = lobes_json(sl->study, cfg.tool.teeth);
        j["open_b_lim_mm"] = sl->open_mm;
        j["below_open"] = sl->below_open;
        j["bands"] = sl->bands;
        j["config"] = sl->config;
        r["scheduled"] = j;
        r["gain"]["scheduled_min_b_lim_change_pct"] = finite_or_null(pct_change(r["min_b_lim_mm"], j["min_b_lim_mm"]));
        r["gain"]["scheduled_at_spindle_change_pct"] =
            finite_or_null(pct_change(r["at_rpm"].back()["b_lim_mm"], j["at_rpm"].back()["b_lim_mm"]));
      }
  }
  return r;
}

json cut_verdict_json(const CutVerdict& v) {
  auto curve = [](const CutCurve& c) {
    return json{{"min_mm", c.min_mm},
                {"min_rpm", c.min_rpm},
                {"mean_ratio", c.mean_ratio},
                {"worse_share", c.worse_share},
                {"worst_ratio", c.worst_ratio},
                {"worst_rpm", c.worst_rpm},
                {"better_share", c.better_share},
                {"at_job_mm", c.at_job_mm},
                {"limit_mm", c.mm}};
  };
  json j = {{"job", v.job},
            {"method", v.method},
            {"tolerance", v.tolerance},
            {"rpm", v.rpm},
            {"job_rpm", v.job_rpm},
            {"open", curve(v.open)},
            {"fixed", curve(v.fixed)},
            {"fixed_gain_ns_per_m", v.fixed_gain_ns_per_m},
            {"verdict", cut_verdict_line(v)}};
  if (v.scheduled) j["scheduled"] = curve(*v.scheduled), j["bands"] = v.bands;
  return j;
}

json sle_report(const config::MillingConfig& cfg, const StudyOptions& o) {
  const auto sc = selected(cfg, o);
  const Structure open(sc, false);
  if (o.damped && !open.has_controller())
    throw config::ConfigError({config::Problem{
        cfg.source, {}, "structures." + sc.name, "--damped needs a part with a controller (a damping configuration)"}});
  json r = sle_json(sle_study(open, cfg));
  r["config"] = cfg.source;
  r["tool"] = tool_text(cfg);
  if (o.damped) r["damped"] = sle_json(sle_study(Structure(sc, true), cfg));
  return r;
}

std::string lobes_table(const json& r) {
  std::ostringstream os;
  auto one = [&](const json& d, const char* label) {
    const std::string method = d["method"].get<std::string>();
    const bool sdm = method != kPreview;
    os << "  " << label << ": minimum limiting depth " << number_text(d["min_b_lim_mm"], "%.3f") << " mm (" << method
       << ") at " << number_text(d["min_rpm"], "%.0f") << " rpm (chatter " << number_text(d["min_chatter_hz"], "%.1f")
       << " Hz); ";
    if (sdm)
      os << d["curve"].size() << " speeds, " << d["steps_per_period"].get<int>() << " steps per tooth period, ";
    else
      os << d["frequency_points"].get<std::size_t>() << " chatter frequencies, ";
    os << number_text(d["diagram_ms"], "%.1f") << " ms\n";
    for (const auto& a : d["at_rpm"]) {
      os << "    at " << number_text(a["rpm"], sdm ? "%9.2f" : "%7.0f") << " rpm: b_lim "
         << number_text(a["b_lim_mm"], "%.3f")
         << (sdm ? " mm (" + method + ", " + a["type"].get<std::string>() + ")" : " mm (zero-order direct test)")
         << (a["b_lim_lobes_mm"].is_null() ? std::string()
                                           : (sdm ? ", zero-order preview " : ", zero-order lobes ") +
                                                 number_text(a["b_lim_lobes_mm"], "%.3f") + " mm")
         << ", chatter " << number_text(a["chatter_hz"], "%.1f") << " Hz\n";
    }
  };
  os << "Stability lobes (" << r["method"].get<std::string>()
     << (r.contains("damped") ? ", damped: " + r["damped"]["method"].get<std::string>() : std::string()) << ") of "
     << r["config"].get<std::string>() << " (structure " << r["structure"].get<std::string>() << ", "
     << r["tool"].get<std::string>() << ")\n";
  one(r, "open  ");
  if (r.contains("damped")) {
    one(r["damped"], "damped");
    os << "  change with active damping: minimum limiting depth "
       << number_text(r["gain"]["min_b_lim_change_pct"], "%+.1f") << " %, at the spindle speed "
       << number_text(r["gain"]["at_spindle_rpm"], "%.0f") << " rpm "
       << number_text(r["gain"]["at_spindle_change_pct"], "%+.1f") << " %"
       << (r["gain"]["at_spindle_change_pct"].is_number() && r["gain"]["at_spindle_change_pct"].get<double>() < 0.0
               ? " (the damper at this fixed gain LOWERS the limit at the job's speed)"
               : "")
       << "\n";
  }
  if (r.contains("scheduled")) {
    const json& s = r["scheduled"];
    one(s, "sched.");
    os << "  change with the speed schedule (" << s["bands"].get<std::size_t>() << " bands of "
       << s["config"].get<std::string>() << "): minimum limiting depth "
       << number_text(r["gain"]["scheduled_min_b_lim_change_pct"], "%+.1f") << " %, at the spindle speed "
       << number_text(r["gain"]["scheduled_at_spindle_change_pct"], "%+.1f")
       << " %; below the open loop (by > 0.5 %) at " << s["below_open"].get<std::size_t>() << " of "
       << s["curve"].size() << " speeds\n";
  }
  for (const auto& n : r["notes"]) os << "  note: " << n.get<std::string>() << '\n';
  if (r.contains("damped"))
    for (const auto& n : r["damped"]["notes"]) os << "  note: " << n.get<std::string>() << '\n';
  return os.str();
}

std::string plot_lobes(const json& r, const std::string& path) {
  std::ostringstream data;
  const bool damped = r.contains("damped"), scheduled = r.contains("scheduled");
  double y_max = 0.0;
  for (const json* d : {&r, damped ? &r["damped"] : nullptr})
    if (d && !(*d)["min_b_lim_mm"].is_null()) y_max = std::max(y_max, 6.0 * (*d)["min_b_lim_mm"].get<double>());
  // One data block per diagram (index 0 open, 1 damped, 2 the speed schedule): their speeds differ where the
  // damped method steps the speed to the loop rate. Full precision: the plotted data is the report's.
  for (const json* d : {&r, damped ? &r["damped"] : nullptr, scheduled ? &r["scheduled"] : nullptr}) {
    if (!d) continue;
    for (const auto& p : (*d)["curve"]) {
      char line[96];
      std::snprintf(line, sizeof line, "%.10g %.10g\n", p["rpm"].get<double>(),
                    p["b_lim_mm"].is_null() ? NAN : p["b_lim_mm"].get<double>());
      data << line;
    }
    data << "\n\n";
  }
  std::ostringstream s;
  s << "set title 'Stability lobes, " << r["structure"].get<std::string>() << ": " << r["tool"].get<std::string>()
    << "'\nset grid\nset xlabel 'spindle speed (rpm)'\nset ylabel 'limiting axial depth b_lim (mm)'\n"
    << "set yrange [0:" << y_max << "]\nset key bottom right opaque box\n";
  s << "set arrow from " << r["spindle_rpm"].get<double>() << ", graph 0 to " << r["spindle_rpm"].get<double>()
    << ", graph 1 nohead dt 3 lc rgb 'gray40'\n";
  s << "plot DATA index 0 u 1:2 w l lw 2 lc rgb '#c0392b' t 'open loop, " << r["method"].get<std::string>() << " (min "
    << number_text(r["min_b_lim_mm"], "%.3f") << " mm)'";
  if (damped)
    s << ", DATA index 1 u 1:2 w l lw 2 lc rgb '#2471a3' t 'active damping at a fixed K, "
      << r["damped"]["method"].get<std::string>() << " (min " << number_text(r["damped"]["min_b_lim_mm"], "%.3f")
      << " mm)'";
  if (scheduled)
    s << ", DATA index 2 u 1:2 w l lw 2.5 lc rgb '#27ae60' t 'active damping by the speed schedule (min "
      << number_text(r["scheduled"]["min_b_lim_mm"], "%.3f") << " mm)'";
  s << '\n';
  return plot::run_gnuplot(s.str(), data.str(), path);
}

std::string sle_table(const json& r) {
  std::ostringstream os;
  os << "Surface location error of " << r["config"].get<std::string>() << " (structure "
     << r["structure"].get<std::string>() << ", " << r["tool"].get<std::string>() << ")\n";
  auto one = [&](const json& d, const char* label) {
    double lo = 1e300, hi = -1e300;
    for (const auto& p : d["map"])
      lo = std::min(lo, p["sle_um"].get<double>()), hi = std::max(hi, p["sle_um"].get<double>());
    os << "  " << label << ": SLE over " << number_text(d["map"].front()["rpm"], "%.0f") << "-"
       << number_text(d["map"].back()["rpm"], "%.0f") << " rpm at the configured cut: " << number_text(json(lo), "%.1f")
       << " to " << number_text(json(hi), "%.1f") << " um";
    if (const int u = d["map_unstable_points"].get<int>(); u > 0)
      os << " (the cut chatters at " << u << " of " << d["map"].size() << " speeds by the "
         << d["stability_method"].get<std::string>() << ": SLE not meaningful there)";
    if (const int p = d["map_preview_points"].get<int>(); p > 0)
      os << " (" << p << " speeds above the " << d["stability_method"].get<std::string>()
         << "'s highest: their stability by the " << kPreview << ")";
    os << '\n';
    if (d["conditions"].empty()) return;
    os << "    cond  rpm    axial  radial  ft     normal  SLE(um)  dyn(um)  offset  radial_cmd(mm)  iter  stable\n";
    for (const auto& c : d["conditions"]) {
      char line[200];
      std::snprintf(
          line, sizeof line, "    %-5s %-6.0f %-6.2f %-7.2f %-6.3f %-7s %-8.1f %-8.1f %-7.1f %-15.4f %-5d %s\n",
          c["name"].get<std::string>().c_str(), c["rpm"].get<double>(), c["axial_mm"].get<double>(),
          c["radial_mm"].get<double>(), c["ft_mm"].get<double>(), c["surface_normal"].get<std::string>().c_str(),
          c["sle_um"].get<double>(), c["sle_dynamic_um"].get<double>(), c["path_offset_um"].get<double>(),
          c["compensated_radial_mm"].get<double>(), c["compensation_iterations"].get<int>(),
          (c["stable"].get<bool>()
               ? "yes (" + c["stability_method"].get<std::string>() + ")"
               : "NO (chatter by the " + c["stability_method"].get<std::string>() + ": SLE not meaningful)")
              .c_str());
      os << line;
    }
  };
  one(r, "open  ");
  if (r.contains("damped")) one(r["damped"], "damped");
  for (const auto& n : r["notes"]) os << "  note: " << n.get<std::string>() << '\n';
  return os.str();
}

std::string plot_sle(const json& r, const std::string& path) {
  std::ostringstream data;
  const bool damped = r.contains("damped");
  double lo = 0.0, hi = 0.0;  // zero stays in view: the level matters, not only the ripple
  for (const json* d : {&r, damped ? &r["damped"] : nullptr})
    for (const auto& p : d ? (*d)["map"] : json::array())
      lo = std::min(lo, p["sle_um"].get<double>()), hi = std::max(hi, p["sle_um"].get<double>());
  // Columns: rpm, open SLE, open SLE where the cut chatters (NaN elsewhere), and the same damped.
  auto chattering = [](const json& p) { return p["stable"].get<bool>() ? NAN : p["sle_um"].get<double>(); };
  for (std::size_t i = 0; i < r["map"].size(); ++i) {
    data << r["map"][i]["rpm"].get<double>() << ' ' << r["map"][i]["sle_um"].get<double>() << ' '
         << chattering(r["map"][i]);
    if (damped)
      data << ' ' << r["damped"]["map"][i]["sle_um"].get<double>() << ' ' << chattering(r["damped"]["map"][i]);
    data << '\n';
  }
  std::ostringstream s;
  s << "set title 'Surface location error (mean over the axial depth), " << r["tool"].get<std::string>()
    << "'\nset grid\nset xlabel 'spindle speed (rpm)'\nset ylabel 'SLE (um), + = undercut'\nset key top left\n"
    << "set yrange [" << 1.1 * lo << ":" << 1.1 * hi << "]\n"
    << "plot DATA u 1:2 w l lw 2 lc rgb '#c0392b' t 'open loop', DATA u 1:3 w p pt 2 ps 1.2 lc rgb '#c0392b' t "
    << "'open loop: chatters (" << r["stability_method"].get<std::string>() << "), SLE not meaningful'";
  if (damped)
    s << ", DATA u 1:4 w l lw 2 lc rgb '#2471a3' t 'active damping', DATA u 1:5 w p pt 6 ps 1.2 lc rgb '#2471a3' t "
      << "'active damping: chatters (" << r["damped"]["stability_method"].get<std::string>() << ")'";
  s << '\n';
  return plot::run_gnuplot(s.str(), data.str(), path);
}

void apply_pose(config::MillingConfig& cfg, const std::vector<double>& pose_deg) {
  if (pose_deg.empty()) return;
  bool any = false;
  for (auto& st : cfg.structures)
    for (auto& part : st.parts) {
      if (!part.pose) continue;
      any = true;
      const config::RobotModelConfig m = config::load_robot_model(part.pose->model_path);
      if (auto p = config::pose_problem(m, pose_deg))
        throw config::ConfigError({config::Problem{cfg.source, {}, "--pose", *p}});
      part.pose->joints_deg = pose_deg;
    }
  if (!any)
    throw config::ConfigError({config::Problem{
        cfg.source, {}, "--pose", "the job has no robot pose part (a part with pose: {model, joints_deg})"}});
}

json job_limits_json(const config::Config& cfg, double rpm) {
  if (cfg.spindle.job_resolved.empty()) return nullptr;
  LiveStability live(config::load_milling_config(cfg.spindle.job_resolved), cfg.spindle.structure, {cfg});
  const LiveLimits l = live.compute(rpm, 0, cfg.controller.gain_ns_per_m);
  const auto finite = fields::finite_or_null;
  return {{"rpm", rpm},
          {"depth_mm", live.depth_mm()},
          {"open_mm", finite(l.open_mm)},
          {"open_method", l.open_method},
          {"damped_mm", finite(l.damped_mm)},
          {"damped_method", l.method},
          {"analysed_rpm", l.analysed_rpm},
          {"damped_valid", l.damped_valid}};
}

}  // namespace robodamp::milling
