#include "apps/milling_report.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/gnuplot.hpp"
#include "config/robot_model_config.hpp"
#include "config/milling_config.hpp"
#include "milling/lobes.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/sle.hpp"

namespace robodamp::apps {

using nlohmann::json;

namespace {

// What the zero-order method's depths are: a fast preview, never a promise (docs/milling.md).
constexpr const char* kPreview = "zero-order preview";

json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

double elapsed_ms(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

config::StructureConfig selected(const config::MillingConfig& cfg, const MillingOptions& o) {
  return selected_structure(cfg, o.structure, o.controller_path);
}

// One lobe diagram (open or damped) with the direct test at the requested speeds.
json lobes_json(const milling::Structure& structure, const config::MillingConfig& cfg, const std::vector<double>& rpms) {
  const auto t0 = std::chrono::steady_clock::now();
  const milling::LobeModel model(structure, milling::chatter_process(cfg.tool, cfg.material, cfg.cut), cfg.lobes);
  const milling::LobeDiagram d = model.diagram();
  json j;
  j["structure"] = structure.name();
  j["closed_loop"] = structure.damped();
  j["frequency_points"] = d.frequency_points;
  j["curve"] = json::array();
  for (const auto& p : d.curve)
    j["curve"].push_back({{"rpm", p.rpm}, {"b_lim_mm", finite_or_null(p.b_lim_m * 1e3)},
                          {"chatter_hz", std::isfinite(p.b_lim_m) ? json(p.chatter_hz) : json(nullptr)}, {"lobe", p.lobe}});
  j["min_b_lim_mm"] = finite_or_null(d.minimum.b_lim_m * 1e3);
  j["min_rpm"] = d.minimum.rpm;
  j["min_chatter_hz"] = d.minimum.chatter_hz;
  j["diagram_ms"] = elapsed_ms(t0);
  j["method"] = kPreview;
  j["at_rpm"] = json::array();
  for (double rpm : rpms) {
    const auto zoa = model.limit_at(rpm);
    const double direct = model.critical_depth_m(rpm);
    j["at_rpm"].push_back({{"rpm", rpm},
                           {"b_lim_mm", finite_or_null(direct * 1e3)},
                           {"b_lim_lobes_mm", zoa ? json(zoa->b_lim_m * 1e3) : json(nullptr)},
                           {"chatter_hz", zoa ? json(zoa->chatter_hz) : json(nullptr)},
                           {"lobe", zoa ? json(zoa->lobe) : json(nullptr)}});
  }
  j["notes"] = structure.notes();
  return j;
}

// The lobe diagram by the accurate method (milling/accurate_stability.hpp): semi-discretization of the
// open-loop structure, or of the sampled damped loop; the critical depth at time_domain.sdm_points speeds
// over the lobes range (those the method can step), each from the zero-order limit there as the first guess.
json sdm_json(const milling::Structure& structure, const config::MillingConfig& cfg, const std::vector<double>& rpms) {
  const auto t0 = std::chrono::steady_clock::now();
  const milling::AccurateStability truth(structure, cfg);
  for (double rpm : rpms)
    if (auto p = truth.speed_problem(rpm))
      throw config::ConfigError({config::Problem{cfg.source, {}, "--rpm", *p + "; --method zoa previews it"}});
  config::LobesConfig grid = cfg.lobes;
  grid.points = cfg.time_domain.sdm_points;
  const milling::LobeModel zoa(structure, milling::chatter_process(cfg.tool, cfg.material, cfg.cut), grid);
  // Progress on stderr: the open loop of a many-mode structure takes minutes.
  const milling::AccurateDiagram diagram = milling::accurate_diagram(structure, cfg, 0, [&](std::size_t done, std::size_t of) {
    if (done % 20 == 0 || done == of)
      std::cerr << "[lobes " << truth.method() << "] " << done << "/" << of << " speeds, " << elapsed_ms(t0) / 1000.0 << " s\n";
  });
  const std::vector<milling::SdmPoint>& curve = diagram.curve;
  std::vector<double> at_guess;
  for (double rpm : rpms) at_guess.push_back(zoa.critical_depth_m(rpm) * 1e3);
  const std::vector<milling::SdmPoint> at = truth.critical(rpms, at_guess);
  json j;
  j["structure"] = structure.name();
  j["closed_loop"] = structure.damped();
  j["method"] = truth.method();
  j["steps_per_period"] = truth.grid_per_period();
  j["curve"] = json::array();
  double best = 1e300, best_rpm = 0.0, best_hz = 0.0;
  for (const auto& s : curve) {
    j["curve"].push_back({{"rpm", s.rpm}, {"b_lim_mm", finite_or_null(s.critical_depth_mm)}, {"chatter_hz", s.chatter_hz},
                          {"type", milling::to_string(s.type)}});
    if (s.critical_depth_mm < best) best = s.critical_depth_mm, best_rpm = s.rpm, best_hz = s.chatter_hz;
  }
  j["min_b_lim_mm"] = finite_or_null(best);
  j["min_rpm"] = best_rpm;
  j["min_chatter_hz"] = best_hz;
  j["frequency_points"] = 0;
  j["at_rpm"] = json::array();
  for (std::size_t i = 0; i < rpms.size(); ++i)
    j["at_rpm"].push_back({{"rpm", at[i].rpm}, {"requested_rpm", rpms[i]}, {"b_lim_mm", finite_or_null(at[i].critical_depth_mm)},
                           {"chatter_hz", at[i].chatter_hz}, {"type", milling::to_string(at[i].type)},
                           {"b_lim_lobes_mm", finite_or_null(at_guess[i])}});
  j["diagram_ms"] = elapsed_ms(t0);
  j["notes"] = structure.notes();
  if (diagram.speeds_left_out > 0)
    j["notes"].push_back("the " + truth.method() + " stops at " + std::to_string(static_cast<int>(truth.max_rpm())) +
                         " rpm (10 loop periods per tooth period): " + std::to_string(diagram.speeds_left_out) +
                         " speeds above it left out; --method zoa previews them");
  return j;
}

double pct_change(const json& open, const json& damped) {
  if (open.is_null() || damped.is_null()) return NAN;
  return (damped.get<double>() / open.get<double>() - 1.0) * 100.0;
}

std::string fmt(const json& v, const char* format) {
  if (v.is_null()) return "-";
  char b[64];
  std::snprintf(b, sizeof b, format, v.get<double>());
  return b;
}

std::string lobes_table(const json& r) {
  std::ostringstream os;
  auto one = [&](const json& d, const char* label) {
    const std::string method = d["method"].get<std::string>();
    const bool sdm = method != kPreview;
    os << "  " << label << ": minimum limiting depth " << fmt(d["min_b_lim_mm"], "%.3f") << " mm (" << method << ") at "
       << fmt(d["min_rpm"], "%.0f") << " rpm (chatter " << fmt(d["min_chatter_hz"], "%.1f") << " Hz); ";
    if (sdm)
      os << d["curve"].size() << " speeds, " << d["steps_per_period"].get<int>() << " steps per tooth period, ";
    else
      os << d["frequency_points"].get<std::size_t>() << " chatter frequencies, ";
    os << fmt(d["diagram_ms"], "%.1f") << " ms\n";
    for (const auto& a : d["at_rpm"]) {
      os << "    at " << fmt(a["rpm"], sdm ? "%9.2f" : "%7.0f") << " rpm: b_lim " << fmt(a["b_lim_mm"], "%.3f")
         << (sdm ? " mm (" + method + ", " + a["type"].get<std::string>() + "), zero-order preview "
                 : " mm (zero-order direct test), zero-order lobes ")
         << fmt(a["b_lim_lobes_mm"], "%.3f") << " mm, chatter " << fmt(a["chatter_hz"], "%.1f") << " Hz\n";
    }
  };
  os << "Stability lobes (" << r["method"].get<std::string>()
     << (r.contains("damped") ? ", damped: " + r["damped"]["method"].get<std::string>() : std::string()) << ") of "
     << r["config"].get<std::string>() << " (structure " << r["structure"].get<std::string>() << ", "
     << r["tool"].get<std::string>() << ")\n";
  one(r, "open  ");
  if (r.contains("damped")) {
    one(r["damped"], "damped");
    os << "  change with active damping: minimum limiting depth " << fmt(r["gain"]["min_b_lim_change_pct"], "%+.1f")
       << " %, at the spindle speed " << fmt(r["gain"]["at_spindle_rpm"], "%.0f") << " rpm "
       << fmt(r["gain"]["at_spindle_change_pct"], "%+.1f") << " %\n";
  }
  for (const auto& n : r["notes"]) os << "  note: " << n.get<std::string>() << '\n';
  if (r.contains("damped"))
    for (const auto& n : r["damped"]["notes"]) os << "  note: " << n.get<std::string>() << '\n';
  return os.str();
}

std::string plot_lobes(const json& r, const std::string& path) {
  std::ostringstream data;
  const bool damped = r.contains("damped");
  double y_max = 0.0;
  for (const json* d : {&r, damped ? &r["damped"] : nullptr})
    if (d && !(*d)["min_b_lim_mm"].is_null()) y_max = std::max(y_max, 6.0 * (*d)["min_b_lim_mm"].get<double>());
  // One data block per diagram (index 0 open, 1 damped): their speeds differ where the damped method
  // steps the speed to the loop rate. Full precision: the plotted data is the report's.
  for (const json* d : {&r, damped ? &r["damped"] : nullptr}) {
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
    << fmt(r["min_b_lim_mm"], "%.3f") << " mm)'";
  if (damped)
    s << ", DATA index 1 u 1:2 w l lw 2 lc rgb '#2471a3' t 'active damping, " << r["damped"]["method"].get<std::string>()
      << " (min " << fmt(r["damped"]["min_b_lim_mm"], "%.3f") << " mm)'";
  s << '\n';
  return run_gnuplot(s.str(), data.str(), path);
}

std::string tool_text(const config::MillingConfig& c) {
  std::ostringstream os;
  os << c.tool.diameter_mm << " mm " << c.tool.teeth << "-tooth " << to_string(c.tool.kind) << ", "
     << c.cut.radial_mm << " mm radial " << to_string(c.cut.mode) << " milling, " << c.material.name;
  return os.str();
}

int finish(const json& report, const MillingOptions& o, const std::string& command, const std::string& table,
           std::string (*plot)(const json&, const std::string&)) {
  const std::string target = plot_file(o.plot_dir, o.plot_path, command + ".png");
  return print_report(report.dump(2), o.json, command, table, target, [&] { return plot(report, target); }, target);
}

// --- SLE -------------------------------------------------------------------------------------------

json sle_json(const milling::Structure& structure, const config::MillingConfig& cfg) {
  const auto cutter = milling::cutter_from(cfg.tool);
  const auto& s = cfg.sle;
  json j;
  j["structure"] = structure.name();
  j["closed_loop"] = structure.damped();
  j["map"] = json::array();
  const milling::CutConditions cut{cfg.cut.mode, cfg.cut.radial_mm, cfg.cut.axial_mm, cfg.cut.feed_per_tooth_mm};
  // SLE assumes a stable cut: the lobes at the map's speeds say where the configured depth chatters.
  config::LobesConfig at_map = cfg.lobes;
  at_map.rpm_min = s.rpm_min;
  at_map.rpm_max = s.rpm_max;
  at_map.points = s.points;
  at_map.log_spacing = false;
  const auto lobes =
      milling::LobeModel(structure, milling::chatter_process(cfg.tool, cfg.material, cfg.cut), at_map).diagram();
  // Whether the configured depth chatters at each speed: the accurate method where it can step the speed,
  // the zero-order preview above that (the damped loop's highest speed), each point labelled.
  const milling::AccurateStability truth(structure, cfg);
  std::vector<double> speeds;
  for (const auto& p : lobes.curve)
    if (p.rpm <= truth.max_rpm()) speeds.push_back(p.rpm);
  const std::vector<bool> accurate = truth.stable(cfg.cut.axial_mm, speeds);
  int chatter = 0, previewed = 0;
  for (int i = 0; i < s.points; ++i) {
    const auto idx = static_cast<std::size_t>(i);
    const double rpm = lobes.curve[idx].rpm;
    const auto r = milling::surface_location_error(structure, cutter, cfg.material, cut, cfg.cut.feed_axis, rpm,
                                                   s.axial_slices, s.harmonics);
    const double b_lim = lobes.curve[idx].b_lim_m;
    const bool by_truth = idx < accurate.size();
    const bool stable = by_truth ? accurate[idx] : cfg.cut.axial_mm * 1e-3 < b_lim;
    chatter += stable ? 0 : 1;
    previewed += by_truth ? 0 : 1;
    j["map"].push_back({{"rpm", rpm}, {"sle_um", r.sle_um}, {"sle_min_um", r.min_um}, {"sle_max_um", r.max_um},
                        {"b_lim_preview_mm", finite_or_null(b_lim * 1e3)}, {"stable", stable},
                        {"stability_method", by_truth ? truth.method() : std::string(kPreview)}});
  }
  j["map_unstable_points"] = chatter;
  j["stability_method"] = truth.method();  // the map's and the conditions' stable flags (docs/milling.md)
  j["map_preview_points"] = previewed;     // above the accurate method's highest speed
  j["conditions"] = json::array();
  // One stability model per immersion and feed axis, shared by the conditions that cut with them.
  std::map<std::pair<double, config::Axis>, std::unique_ptr<milling::AccurateStability>> stability_models;
  for (const auto& c : cfg.conditions) {
    for (const config::Axis normal : s.surface_normals) {
      const config::Axis feed = normal == config::Axis::kY ? config::Axis::kX : config::Axis::kY;
      const milling::CutConditions cc{cfg.cut.mode, c.radial_mm, c.axial_mm, c.feed_per_tooth_mm};
      const double offset_um = 1000.0 * (normal == config::Axis::kX ? c.path_offset_x_mm : c.path_offset_y_mm);
      const auto r = milling::surface_location_error(structure, cutter, cfg.material, cc, feed, c.rpm, s.axial_slices,
                                                     s.harmonics);
      const auto comp = milling::compensate(structure, cutter, cfg.material, cc, feed, c.rpm, offset_um, s);
      // SLE assumes a stable cut: say whether this one is, with this immersion and feed axis.
      config::CutConfig cut_c = cfg.cut;
      cut_c.radial_mm = c.radial_mm;
      cut_c.feed_axis = feed;
      auto& model = stability_models[{c.radial_mm, feed}];
      if (!model) model = std::make_unique<milling::AccurateStability>(structure, cfg, cut_c);
      const bool by_truth = !model->speed_problem(c.rpm);
      const bool stable =
          by_truth ? model->stable(c.axial_mm, c.rpm)
                   : milling::LobeModel(structure, milling::chatter_process(cfg.tool, cfg.material, cut_c), cfg.lobes)
                         .stable(c.axial_mm * 1e-3, c.rpm);
      j["conditions"].push_back({{"name", c.name},
                                 {"rpm", c.rpm},
                                 {"axial_mm", c.axial_mm},
                                 {"radial_mm", c.radial_mm},
                                 {"ft_mm", c.feed_per_tooth_mm},
                                 {"surface_normal", to_string(normal)},
                                 {"sle_um", r.sle_um + offset_um},
                                 {"sle_dynamic_um", r.sle_um},
                                 {"path_offset_um", offset_um},
                                 {"sle_min_um", r.min_um + offset_um},
                                 {"sle_max_um", r.max_um + offset_um},
                                 {"mean_normal_force_n", r.mean_normal_force_n},
                                 {"compensated_radial_mm", comp.radial_mm},
                                 {"compensation_residual_um", comp.residual_um},
                                 {"compensation_iterations", comp.iterations},
                                 {"compensation_converged", comp.converged},
                                 {"stable", stable},
                                 {"stability_method", by_truth ? model->method() : std::string(kPreview)}});
    }
  }
  j["notes"] = structure.notes();
  return j;
}

std::string sle_table(const json& r) {
  std::ostringstream os;
  os << "Surface location error of " << r["config"].get<std::string>() << " (structure "
     << r["structure"].get<std::string>() << ", " << r["tool"].get<std::string>() << ")\n";
  auto one = [&](const json& d, const char* label) {
    double lo = 1e300, hi = -1e300;
    for (const auto& p : d["map"]) lo = std::min(lo, p["sle_um"].get<double>()), hi = std::max(hi, p["sle_um"].get<double>());
    os << "  " << label << ": SLE over " << fmt(d["map"].front()["rpm"], "%.0f") << "-" << fmt(d["map"].back()["rpm"], "%.0f")
       << " rpm at the configured cut: " << fmt(json(lo), "%.1f") << " to " << fmt(json(hi), "%.1f") << " um";
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
      std::snprintf(line, sizeof line, "    %-5s %-6.0f %-6.2f %-7.2f %-6.3f %-7s %-8.1f %-8.1f %-7.1f %-15.4f %-5d %s\n",
                    c["name"].get<std::string>().c_str(), c["rpm"].get<double>(), c["axial_mm"].get<double>(),
                    c["radial_mm"].get<double>(), c["ft_mm"].get<double>(), c["surface_normal"].get<std::string>().c_str(),
                    c["sle_um"].get<double>(), c["sle_dynamic_um"].get<double>(), c["path_offset_um"].get<double>(),
                    c["compensated_radial_mm"].get<double>(), c["compensation_iterations"].get<int>(),
                    (c["stable"].get<bool>() ? "yes (" + c["stability_method"].get<std::string>() + ")"
                                             : "NO (chatter by the " + c["stability_method"].get<std::string>() + ": SLE not meaningful)").c_str());
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
    data << r["map"][i]["rpm"].get<double>() << ' ' << r["map"][i]["sle_um"].get<double>() << ' ' << chattering(r["map"][i]);
    if (damped) data << ' ' << r["damped"]["map"][i]["sle_um"].get<double>() << ' ' << chattering(r["damped"]["map"][i]);
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
  return run_gnuplot(s.str(), data.str(), path);
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
  throw config::ConfigError({config::Problem{cfg.source, {}, "--structure", "= '" + name + "' is not one of: " + known}});
}

json lobes_report(const config::MillingConfig& cfg, const MillingOptions& o) {
  const auto sc = selected(cfg, o);
  std::vector<double> rpms = o.rpm;
  rpms.push_back(cfg.cut.spindle_rpm);
  const milling::Structure open(sc, false);
  if (o.damped && !open.has_controller())
    throw config::ConfigError({config::Problem{cfg.source, {}, "structures." + sc.name,
                                               "--damped needs a part with a controller (a damping configuration)"}});
  json r = o.method == "sdm" ? sdm_json(open, cfg, rpms) : lobes_json(open, cfg, rpms);
  r["config"] = cfg.source;
  r["tool"] = tool_text(cfg);
  r["spindle_rpm"] = cfg.cut.spindle_rpm;
  if (cfg.cut.mode == config::MillingMode::kUp)
    r["notes"].push_back("up milling starts each chip at zero thickness: a start-up transient can take the tool out of "
                         "the cut and chatter below these linear limits (docs/milling.md); `robodamp cut --critical` "
                         "simulates it");
  if (o.damped) {
    const milling::Structure closed(sc, true);
    r["damped"] = o.method == "sdm" ? sdm_json(closed, cfg, rpms) : lobes_json(closed, cfg, rpms);
    r["gain"] = {{"min_b_lim_change_pct", finite_or_null(pct_change(r["min_b_lim_mm"], r["damped"]["min_b_lim_mm"]))},
                 {"at_spindle_rpm", cfg.cut.spindle_rpm},
                 {"at_spindle_change_pct",
                  finite_or_null(pct_change(r["at_rpm"].back()["b_lim_mm"], r["damped"]["at_rpm"].back()["b_lim_mm"]))}};
  }
  return r;
}

int print_lobes(const json& r, const MillingOptions& o) { return finish(r, o, "lobes", lobes_table(r), plot_lobes); }

json sle_report(const config::MillingConfig& cfg, const MillingOptions& o) {
  const auto sc = selected(cfg, o);
  const milling::Structure open(sc, false);
  if (o.damped && !open.has_controller())
    throw config::ConfigError({config::Problem{cfg.source, {}, "structures." + sc.name,
                                               "--damped needs a part with a controller (a damping configuration)"}});
  json r = sle_json(open, cfg);
  r["config"] = cfg.source;
  r["tool"] = tool_text(cfg);
  if (o.damped) r["damped"] = sle_json(milling::Structure(sc, true), cfg);
  return r;
}

int print_sle(const json& r, const MillingOptions& o) { return finish(r, o, "sle", sle_table(r), plot_sle); }

void add_milling_options(Registry& r, CLI::App* sub, MillingOptions& o, const std::string& command) {
  sub->add_option("--config", o.config_path, "Milling job (YAML, config/milling/)")->check(CLI::ExistingFile);
  sub->add_option("--structure", o.structure, "Which of the job's structures (default: its `structure`)");
  r.json(sub, o.json, "The report (every speed, the limits and their methods)");
  r.plot_dir(sub, o.plot_dir, command + ".png");
  r.deprecated(sub->add_option("--plot", o.plot_path, "Write the plot to this file (PNG)"), "--plot-dir DIR");
  sub->add_flag("--damped", o.damped, "Also with the damping controller's loop closed, overlaid");
  sub->add_option("--controller", o.controller_path, "Damping configuration to use instead of the job's (compare compensators)")
      ->check(CLI::ExistingFile);
}

void apply_pose(config::MillingConfig& cfg, const MillingOptions& o) {
  if (o.pose_deg.empty()) return;
  bool any = false;
  for (auto& st : cfg.structures)
    for (auto& part : st.parts) {
      if (!part.pose) continue;
      any = true;
      const config::RobotModelConfig m = config::load_robot_model(part.pose->model_path);
      if (auto p = config::pose_problem(m, o.pose_deg))
        throw config::ConfigError({config::Problem{cfg.source, {}, "--pose", *p}});
      part.pose->joints_deg = o.pose_deg;
    }
  if (!any)
    throw config::ConfigError({config::Problem{cfg.source, {}, "--pose",
                                               "the job has no robot pose part (a part with pose: {model, joints_deg})"}});
}

}  // namespace robodamp::apps
