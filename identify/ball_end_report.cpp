#include "identify/ball_end_report.hpp"

#include <cmath>
#include <sstream>

#include "fields/printf.hpp"

namespace robodamp::identify {

namespace {

using fields::printf_string;

nlohmann::json terms(const std::vector<Estimate>& poly) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& e : poly) j.push_back({{"value", e.value}, {"ci95", e.ci95}});
  return j;
}

std::string polynomial_line(const char* name, const std::vector<Estimate>& p) {
  std::string line = printf_string("  %s:", name);
  for (std::size_t i = 0; i < p.size(); ++i) line += printf_string("  k%zu %.4g +- %.3g", i, p[i].value, p[i].ci95);
  return line + "  N/mm^2\n";
}

std::string text_of(const BallEndFit& f, const BallEndTest& t) {
  std::string s = printf_string(
      "Ball-end cutting coefficients from %d slot runs (%d teeth, %.3g mm, helix %.3g deg), shear terms of order %d "
      "in kappa (rad):\n",
      f.runs, t.teeth, t.diameter_mm, t.helix_deg, t.order);
  s += polynomial_line("Ktc", f.ktc) + polynomial_line("Krc", f.krc) + polynomial_line("Kac", f.kac);
  s += printf_string("  Kte %.4g +- %.3g, Kre %.4g +- %.3g, Kae %.4g +- %.3g N/mm\n", f.kte.value, f.kte.ci95,
                     f.kre.value, f.kre.ci95, f.kae.value, f.kae.ci95);
  s += printf_string("  at kappa = 1 rad: Ktc %.4g, Krc %.4g, Kac %.4g N/mm^2\n",
                     polynomial_at(f.ktc, kBallEndTableKappaRad), polynomial_at(f.krc, kBallEndTableKappaRad),
                     polynomial_at(f.kac, kBallEndTableKappaRad));
  s += printf_string("  R^2 %.4f (y) %.4f (x, z), residual RMS %.4g N, condition number %.3g (refused above %.0e)\n",
                     f.r2_y, f.r2_xz, f.residual_rms_n, f.condition_number, kMaxConditionNumber);
  bool wide = false;
  for (const auto* p : {&f.ktc, &f.krc, &f.kac})
    for (const auto& e : *p) wide = wide || e.ci95 > std::abs(e.value);
  if (wide) s += "  note: some 95 % intervals are wider than their values: the runs do not determine them\n";
  return s;
}

}  // namespace

double polynomial_at(const std::vector<Estimate>& poly, double kappa_rad) {
  double v = 0.0, kp = 1.0;
  for (const auto& e : poly) v += e.value * kp, kp *= kappa_rad;
  return v;
}

BallEndReport ball_end_report(const BallEndFit& f, const BallEndTest& t, const std::string& source) {
  BallEndReport r;
  r.text = text_of(f, t);
  r.json = {{"ktc_n_per_mm2", terms(f.ktc)},
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
            {"order", t.order}};
  std::ostringstream y;
  y << "material:                 # robodamp identify cutting --ball-end, " << f.runs << " runs, at kappa = 1 rad\n"
    << "  name: identified from " << source << "\n"
    << "  kt_n_per_mm2: " << polynomial_at(f.ktc, kBallEndTableKappaRad)
    << "\n  kn_n_per_mm2: " << polynomial_at(f.krc, kBallEndTableKappaRad) << "\n  kte_n_per_mm: " << f.kte.value
    << "\n  kne_n_per_mm: " << f.kre.value << "\n  kac_n_per_mm2: " << polynomial_at(f.kac, kBallEndTableKappaRad)
    << "\n";
  r.yaml = y.str();
  return r;
}

}  // namespace robodamp::identify
