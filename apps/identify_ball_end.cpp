// `robodamp identify cutting --ball-end`: the shear coefficients of a ball-end mill as polynomials in the
// axial angle and the edge coefficients, from slot-milling mean forces (the ball-end bone study's method; identify/
// ball_end.hpp, docs/identification.md), with 95 % intervals, R^2, the residual RMS and the condition
// number; JSON and a material: block (the coefficients at kappa = 1 rad, as Tian et al. (2024) tabulates them).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/identify_command.hpp"
#include "identify/ball_end.hpp"

namespace robodamp::apps {

namespace {

constexpr double kTableKappaRad =
    1.0;  // Tian et al. (2024)'s single values are the ball-end bone study's at kappa = 1 rad

double at(const std::vector<identify::Estimate>& poly, double kappa) {
  double v = 0.0, kp = 1.0;
  for (const auto& e : poly) v += e.value * kp, kp *= kappa;
  return v;
}

nlohmann::json terms(const std::vector<identify::Estimate>& poly) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& e : poly) j.push_back({{"value", e.value}, {"ci95", e.ci95}});
  return j;
}

}  // namespace

int run_identify_ball_end(const IdentifyArgs& a) {
  if (a.csv_path.empty() || a.teeth == 0 || a.diameter_mm == 0.0) {
    std::cerr << "robodamp identify cutting --ball-end: --csv, --teeth and --diameter-mm are required\n";
    return 2;
  }
  const identify::BallEndTest t{a.teeth, a.diameter_mm, a.helix_deg, a.order};
  identify::BallEndFit f;
  try {
    f = identify::identify_ball_end(identify::read_ball_end_csv(a.csv_path), t);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify cutting --ball-end: " << e.what() << '\n';
    return 2;
  }
  std::printf(
      "Ball-end cutting coefficients from %d slot runs (%d teeth, %.3g mm, helix %.3g deg), shear terms of order %d "
      "in kappa (rad):\n",
      f.runs, a.teeth, a.diameter_mm, a.helix_deg, a.order);
  auto poly = [](const char* name, const std::vector<identify::Estimate>& p) {
    std::printf("  %s:", name);
    for (std::size_t i = 0; i < p.size(); ++i) std::printf("  k%zu %.4g +- %.3g", i, p[i].value, p[i].ci95);
    std::printf("  N/mm^2\n");
  };
  poly("Ktc", f.ktc), poly("Krc", f.krc), poly("Kac", f.kac);
  std::printf("  Kte %.4g +- %.3g, Kre %.4g +- %.3g, Kae %.4g +- %.3g N/mm\n", f.kte.value, f.kte.ci95, f.kre.value,
              f.kre.ci95, f.kae.value, f.kae.ci95);
  std::printf("  at kappa = 1 rad: Ktc %.4g, Krc %.4g, Kac %.4g N/mm^2\n", at(f.ktc, kTableKappaRad),
              at(f.krc, kTableKappaRad), at(f.kac, kTableKappaRad));
  std::printf("  R^2 %.4f (y) %.4f (x, z), residual RMS %.4g N, condition number %.3g (refused above %.0e)\n", f.r2_y,
              f.r2_xz, f.residual_rms_n, f.condition_number, identify::kMaxConditionNumber);
  bool wide = false;
  for (const auto* p : {&f.ktc, &f.krc, &f.kac})
    for (const auto& e : *p) wide = wide || e.ci95 > std::abs(e.value);
  if (wide) std::printf("  note: some 95 %% intervals are wider than their values: the runs do not determine them\n");
  if (a.json.given) {
    const nlohmann::json j = {{"ktc_n_per_mm2", terms(f.ktc)},
                              {"krc_n_per_mm2", terms(f.krc)},
                              {"kac_n_per_mm2", terms(f.kac)},
                              {"kte_n_per_mm", {{"value", f.kte.value}, {"ci95", f.kte.ci95}}},
                              {"kre_n_per_mm", {{"value", f.kre.value}, {"ci95", f.kre.ci95}}},
                              {"kae_n_per_mm", {{"value", f.kae.value}, {"ci95", f.kae.ci95}}},
                              {"r2_y", f.r2_y},
                              {"r2_xz", f.r2_xz},
                              {"residual_rms_n", f.residual_rms_n},
                              {"condition_number", f.condition_number},
                              {"runs", f.runs},
                              {"order", a.order}};
    if (!emit_json(a.json, j.dump(2), "identify")) return 1;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
  }
  if (!a.yaml_path.empty()) {
    std::ofstream y(a.yaml_path);
    y << "material:                 # robodamp identify cutting --ball-end, " << f.runs << " runs, at kappa = 1 rad\n"
      << "  name: identified from " << a.csv_path << "\n"
      << "  kt_n_per_mm2: " << at(f.ktc, kTableKappaRad) << "\n  kn_n_per_mm2: " << at(f.krc, kTableKappaRad)
      << "\n  kte_n_per_mm: " << f.kte.value << "\n  kne_n_per_mm: " << f.kre.value
      << "\n  kac_n_per_mm2: " << at(f.kac, kTableKappaRad) << "\n";
    std::printf("wrote %s\n", a.yaml_path.c_str());
  }
  return 0;
}

}  // namespace robodamp::apps
