#include "milling/studies.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "milling/accurate_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/sle.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

namespace {

double elapsed_ms(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

LobeStudy zero_order_lobe_study(const Structure& structure, const config::MillingConfig& cfg,
                                const std::vector<double>& rpms) {
  const auto t0 = std::chrono::steady_clock::now();
  const LobeModel model(structure, chatter_process(cfg.tool, cfg.material, cfg.cut), cfg.lobes);
  const LobeDiagram d = model.diagram();
  LobeStudy s;
  s.structure = structure.name();
  s.closed_loop = structure.damped();
  s.method = kZeroOrderPreview;
  s.frequency_points = d.frequency_points;
  for (const auto& p : d.curve)
    s.curve.push_back({p.rpm, p.b_lim_mm,
                       std::isfinite(p.b_lim_mm) ? std::optional<double>(p.chatter_hz) : std::nullopt, p.lobe,
                       std::nullopt});
  s.min_b_lim_mm = d.minimum.b_lim_mm;
  s.min_rpm = d.minimum.rpm;
  s.min_chatter_hz = d.minimum.chatter_hz;
  s.diagram_ms = elapsed_ms(t0);
  for (double rpm : rpms) {
    const auto zoa = model.limit_at(rpm);
    LobeAtSpeed a;
    a.rpm = rpm;
    a.b_lim_mm = model.critical_depth_mm(rpm);
    if (zoa) a.b_lim_lobes_mm = zoa->b_lim_mm, a.chatter_hz = zoa->chatter_hz, a.lobe = zoa->lobe;
    s.at_rpm.push_back(a);
  }
  s.notes = structure.notes();
  return s;
}

LobeStudy accurate_lobe_study(
    const Structure& structure, const config::MillingConfig& cfg, const std::vector<double>& rpms,
    const std::function<void(const std::string&, std::size_t, std::size_t, double)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const AccurateStability truth(structure, cfg);
  for (double rpm : rpms)
    if (auto p = truth.speed_problem(rpm))
      throw config::ConfigError({config::Problem{cfg.source, {}, "--rpm", *p + "; --method zoa previews it"}});
  config::LobesConfig grid = cfg.lobes;
  grid.points = cfg.time_domain.sdm_points;
  const LobeModel zoa(structure, chatter_process(cfg.tool, cfg.material, cfg.cut), grid);
  const AccurateDiagram diagram = accurate_diagram(structure, cfg, 0, [&](std::size_t done, std::size_t of) {
    if (progress) progress(truth.method(), done, of, elapsed_ms(t0) / 1000.0);
  });
  std::vector<double> at_guess;
  for (double rpm : rpms) at_guess.push_back(zoa.critical_depth_mm(rpm));
  const std::vector<SdmPoint> at = truth.critical(rpms, at_guess);
  LobeStudy s;
  s.structure = structure.name();
  s.closed_loop = structure.damped();
  s.method = truth.method();
  s.accurate = true;
  s.steps_per_period = truth.grid_per_period();
  double best = 1e300, best_rpm = 0.0, best_hz = 0.0;
  for (const auto& p : diagram.curve) {
    s.curve.push_back({p.rpm, p.critical_depth_mm, p.chatter_hz, std::nullopt, to_string(p.type)});
    if (p.critical_depth_mm < best) best = p.critical_depth_mm, best_rpm = p.rpm, best_hz = p.chatter_hz;
  }
  s.min_b_lim_mm = best;
  s.min_rpm = best_rpm;
  s.min_chatter_hz = best_hz;
  for (std::size_t i = 0; i < rpms.size(); ++i) {
    LobeAtSpeed a;
    a.rpm = at[i].rpm;
    a.requested_rpm = rpms[i];
    a.b_lim_mm = at[i].critical_depth_mm;
    a.chatter_hz = at[i].chatter_hz;
    a.type = to_string(at[i].type);
    if (std::isfinite(at_guess[i])) a.b_lim_lobes_mm = at_guess[i];
    s.at_rpm.push_back(a);
  }
  s.diagram_ms = elapsed_ms(t0);
  s.notes = structure.notes();
  if (diagram.speeds_left_out > 0)
    s.notes.push_back("the " + truth.method() + " stops at " + std::to_string(static_cast<int>(truth.max_rpm())) +
                      " rpm (10 loop periods per tooth period): " + std::to_string(diagram.speeds_left_out) +
                      " speeds above it left out; --method zoa previews them");
  return s;
}

namespace {

// The SLE map at the configured cut: the surface at each speed, and whether the configured depth chatters
// there (the accurate method where it can step the speed, the zero-order preview above that).
void sle_map(const Structure& structure, const config::MillingConfig& cfg, SleStudy& out) {
  const auto cutter = cutter_from(cfg.tool);
  const auto& s = cfg.sle;
  const CutConditions cut{cfg.cut.mode, cfg.cut.radial_mm, cfg.cut.axial_mm, cfg.cut.feed_per_tooth_mm};
  config::LobesConfig at_map = cfg.lobes;
  at_map.rpm_min = s.rpm_min;
  at_map.rpm_max = s.rpm_max;
  at_map.points = s.points;
  at_map.log_spacing = false;
  const auto lobes = LobeModel(structure, chatter_process(cfg.tool, cfg.material, cfg.cut), at_map).diagram();
  const AccurateStability truth(structure, cfg);
  std::vector<double> speeds;
  for (const auto& p : lobes.curve)
    if (p.rpm <= truth.max_rpm()) speeds.push_back(p.rpm);
  const std::vector<bool> accurate = truth.stable(cfg.cut.axial_mm, speeds);
  for (int i = 0; i < s.points; ++i) {
    const auto idx = static_cast<std::size_t>(i);
    const double rpm = lobes.curve[idx].rpm;
    const auto r = surface_location_error(structure, cutter, cfg.material, cut, cfg.cut.feed_axis, rpm, s.axial_slices,
                                          s.harmonics);
    const double b_lim_mm = lobes.curve[idx].b_lim_mm;
    const bool by_truth = idx < accurate.size();
    const bool stable = by_truth ? accurate[idx] : cfg.cut.axial_mm < b_lim_mm;
    out.map_unstable_points += stable ? 0 : 1;
    out.map_preview_points += by_truth ? 0 : 1;
    out.map.push_back({rpm, r.sle_um, r.min_um, r.max_um, b_lim_mm, stable,
                       by_truth ? truth.method() : std::string(kZeroOrderPreview)});
  }
  out.stability_method = truth.method();
}

// Each test condition at each surface normal: its SLE with the measured path offset, the compensation, and
// whether the cut is stable with that immersion and feed axis (one stability model per pair, shared).
void sle_conditions(const Structure& structure, const config::MillingConfig& cfg, SleStudy& out) {
  const auto cutter = cutter_from(cfg.tool);
  const auto& s = cfg.sle;
  std::map<std::pair<double, config::Axis>, std::unique_ptr<AccurateStability>> stability_models;
  for (const auto& c : cfg.conditions) {
    for (const config::Axis normal : s.surface_normals) {
      const config::Axis feed = normal == config::Axis::kY ? config::Axis::kX : config::Axis::kY;
      const CutConditions cc{cfg.cut.mode, c.radial_mm, c.axial_mm, c.feed_per_tooth_mm};
      const double offset_um = 1000.0 * (normal == config::Axis::kX ? c.path_offset_x_mm : c.path_offset_y_mm);
      const auto r =
          surface_location_error(structure, cutter, cfg.material, cc, feed, c.rpm, s.axial_slices, s.harmonics);
      const auto comp = compensate(structure, cutter, cfg.material, cc, feed, c.rpm, offset_um, s);
      config::CutConfig cut_c = cfg.cut;
      cut_c.radial_mm = c.radial_mm;
      cut_c.feed_axis = feed;
      auto& model = stability_models[{c.radial_mm, feed}];
      if (!model) model = std::make_unique<AccurateStability>(structure, cfg, cut_c);
      const bool by_truth = !model->speed_problem(c.rpm);
      const bool stable = by_truth ? model->stable(c.axial_mm, c.rpm)
                                   : LobeModel(structure, chatter_process(cfg.tool, cfg.material, cut_c), cfg.lobes)
                                         .stable(c.axial_mm, c.rpm);
      SleCondition o;
      o.name = c.name, o.rpm = c.rpm, o.axial_mm = c.axial_mm, o.radial_mm = c.radial_mm, o.ft_mm = c.feed_per_tooth_mm;
      o.surface_normal = normal;
      o.sle_um = r.sle_um + offset_um, o.sle_dynamic_um = r.sle_um, o.path_offset_um = offset_um;
      o.sle_min_um = r.min_um + offset_um, o.sle_max_um = r.max_um + offset_um;
      o.mean_normal_force_n = r.mean_normal_force_n;
      o.compensated_radial_mm = comp.radial_mm, o.compensation_residual_um = comp.residual_um;
      o.compensation_iterations = comp.iterations, o.compensation_converged = comp.converged;
      o.stable = stable;
      o.stability_method = by_truth ? model->method() : std::string(kZeroOrderPreview);
      out.conditions.push_back(std::move(o));
    }
  }
}

}  // namespace

SleStudy sle_study(const Structure& structure, const config::MillingConfig& cfg) {
  SleStudy s;
  s.structure = structure.name();
  s.closed_loop = structure.damped();
  sle_map(structure, cfg, s);
  sle_conditions(structure, cfg, s);
  s.notes = structure.notes();
  return s;
}

}  // namespace robodamp::milling
