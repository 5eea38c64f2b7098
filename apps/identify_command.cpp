// `robodamp identify cutting`: cutting coefficients of a flat end mill from mean forces at several feeds
// (docs/identification.md), with their 95 % confidence intervals and the fit's quality figures, as JSON
// and as a `material:` block for milling jobs.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "identify/cutting_coefficients.hpp"

namespace robodamp::apps {

namespace {

struct IdentifyArgs {
  std::string what;
  std::string csv_path, json_path, yaml_path;
  int teeth{0};
  double diameter_mm{0.0}, axial_mm{0.0}, radial_mm{0.0};
  std::string mode{"down"};
};

nlohmann::json estimate(const identify::Estimate& e) { return {{"value", e.value}, {"ci95", e.ci95}}; }

int run_identify(const IdentifyArgs& a) {
  identify::CuttingTest t{a.teeth, a.diameter_mm, a.axial_mm, a.radial_mm,
                          a.mode == "up" ? config::MillingMode::kUp : config::MillingMode::kDown};
  identify::CuttingFit f;
  try {
    if (a.radial_mm > a.diameter_mm)
      throw std::invalid_argument("--radial-mm = " + config::format_number(a.radial_mm) +
                                  " mm is out of range: allowed 0 < value <= --diameter-mm = " +
                                  config::format_number(a.diameter_mm) + " mm");
    f = identify::identify_cutting(identify::read_mean_forces_csv(a.csv_path), t);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify cutting: " << e.what() << '\n';
    return 2;
  }
  std::printf("Cutting coefficients from %d feeds (%d teeth, %.3g mm, %.3g mm axial, %.3g mm radial, %s milling):\n",
              f.samples, a.teeth, a.diameter_mm, a.axial_mm, a.radial_mm, a.mode.c_str());
  auto line = [](const char* name, const identify::Estimate& e, const char* unit) {
    std::printf("  %-4s %10.3f +- %.3f %s (95 %%)\n", name, e.value, e.ci95, unit);
  };
  line("Ktc", f.ktc, "N/mm^2"), line("Krc", f.krc, "N/mm^2"), line("Kac", f.kac, "N/mm^2");
  line("Kte", f.kte, "N/mm"), line("Kre", f.kre, "N/mm"), line("Kae", f.kae, "N/mm");
  std::printf("  R^2 %.6f (x, y) %.6f (z), residual RMS %.4g N, condition number %.3g (refused above %.0e)\n", f.r2_xy,
              f.r2_z, f.residual_rms_n, f.condition_number, identify::kMaxConditionNumber);
  if (!a.json_path.empty()) {
    const nlohmann::json j = {{"ktc_n_per_mm2", estimate(f.ktc)}, {"krc_n_per_mm2", estimate(f.krc)},
                              {"kac_n_per_mm2", estimate(f.kac)}, {"kte_n_per_mm", estimate(f.kte)},
                              {"kre_n_per_mm", estimate(f.kre)},  {"kae_n_per_mm", estimate(f.kae)},
                              {"r2_xy", f.r2_xy}, {"r2_z", f.r2_z}, {"residual_rms_n", f.residual_rms_n},
                              {"condition_number", f.condition_number}, {"samples", f.samples}};
    std::ofstream(a.json_path) << j.dump(2) << '\n';
    std::printf("wrote %s\n", a.json_path.c_str());
  }
  if (!a.yaml_path.empty()) {
    std::ofstream y(a.yaml_path);
    y << "material:                 # robodamp identify cutting, " << f.samples << " feeds, R^2 " << f.r2_xy << "\n"
      << "  name: identified from " << a.csv_path << "\n"
      << "  kt_n_per_mm2: " << f.ktc.value << "\n  kn_n_per_mm2: " << f.krc.value << "\n  kte_n_per_mm: " << f.kte.value
      << "\n  kne_n_per_mm: " << f.kre.value << "\n  kac_n_per_mm2: " << f.kac.value << "\n"
      << "  # Kae = " << f.kae.value << " N/mm (axial edge; the 2D milling models do not use it)\n";
    std::printf("wrote %s\n", a.yaml_path.c_str());
  }
  return 0;
}

}  // namespace

void register_identify(Registry& r) {
  auto a = std::make_shared<IdentifyArgs>();
  CLI::App* sub = r.add("identify", "Identify from measurements: `identify cutting` (cutting coefficients from mean forces)",
                        [a] { return run_identify(*a); });
  sub->add_option("what", a->what, "What to identify: cutting")->required()->check(CLI::IsMember({"cutting"}));
  sub->add_option("--csv", a->csv_path, "Mean forces: feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n")
      ->required()->check(CLI::ExistingFile);
  r.whole_number(sub, "--teeth", a->teeth, {"(teeth)", 1, 32}, "Teeth of the tool")->required();
  r.number(sub, "--diameter-mm", a->diameter_mm, {"mm", 0.0, 200.0, true, false}, "Tool diameter")->required();
  r.number(sub, "--axial-mm", a->axial_mm, {"mm", 0.0, 100.0, true, false}, "Axial depth of the tests")->required();
  r.number(sub, "--radial-mm", a->radial_mm, {"mm", 0.0, 200.0, true, false, "and at most --diameter-mm"},
           "Radial depth of the tests (the diameter: slotting)")->required();
  sub->add_option("--mode", a->mode, "down or up milling")->check(CLI::IsMember({"down", "up"}));
  sub->add_option("--json", a->json_path, "Write the coefficients and quality figures as JSON");
  sub->add_option("--yaml", a->yaml_path, "Write a material: block for milling jobs");
}

}  // namespace robodamp::apps
