// `robodamp identify cutting`: cutting coefficients of a flat end mill from mean forces (--csv) or from the
// raw force records of the tests (--records: each record's steady cut found, its drift removed, its mean
// taken), with 95 % intervals, R^2 per axis and a warning where a force is not linear in the feed.
// docs/identification.md.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/identify_command.hpp"
#include "identify/cutting_coefficients.hpp"
#include "identify/cutting_records.hpp"

namespace robodamp::apps {

namespace {

namespace fs = std::filesystem;

nlohmann::json estimate(const identify::Estimate& e) { return {{"value", e.value}, {"ci95", e.ci95}}; }

// The tests: a table (--tests), or the record files (--records, a directory's files in name order) with
// --feeds-mm and --rpm.
std::vector<identify::RecordTest> record_tests(const IdentifyArgs& a) {
  if (!a.tests_path.empty()) {
    if (!a.records.empty() || !a.feeds_mm.empty())
      throw std::invalid_argument("--tests names the records and their feeds: leave out --records and --feeds-mm");
    return identify::read_record_tests(a.tests_path);
  }
  std::vector<std::string> files;
  for (const auto& r : a.records) {
    if (fs::is_directory(r)) {
      std::vector<std::string> in;
      for (const auto& e : fs::directory_iterator(r))
        if (e.is_regular_file()) in.push_back(e.path().string());
      std::sort(in.begin(), in.end());
      files.insert(files.end(), in.begin(), in.end());
    } else {
      files.push_back(r);
    }
  }
  if (files.size() != a.feeds_mm.size() || a.rpm <= 0.0)
    throw std::invalid_argument(
        std::to_string(files.size()) + " records and " + std::to_string(a.feeds_mm.size()) +
        " feeds: give one --feeds-mm value per record (in name order) and --rpm, or a --tests table "
        "(file, feed_per_tooth_mm, spindle_rpm)");
  std::vector<identify::RecordTest> out;
  for (std::size_t i = 0; i < files.size(); ++i) out.push_back({files[i], a.feeds_mm[i], a.rpm});
  return out;
}

std::vector<identify::MeanForces> means_from_records(const IdentifyArgs& a, nlohmann::json& j) {
  identify::RecordSettings s;
  s.axes = identify::parse_axes(a.axes);
  s.force_on_workpiece = a.force_on == "workpiece";
  std::vector<identify::MeanForces> out;
  j = nlohmann::json::array();
  for (const auto& test : record_tests(a)) {
    const identify::ForceRecord r = identify::read_force_record(test.file);
    const identify::SteadyCut c = identify::steady_cut(r, test.spindle_rpm, test.feed_per_tooth_mm, s);
    std::printf(
        "  %s: %.4g mm/tooth at %.0f rpm: steady %.3f-%.3f s (%d whole revolutions of %d cutting; means within %.2f "
        "%%), "
        "drift from %s; on the tool Fx %.2f Fy %.2f Fz %.2f N\n",
        test.file.c_str(), test.feed_per_tooth_mm, test.spindle_rpm, c.start_s, c.end_s, c.revolutions,
        c.cutting_revolutions, c.spread_pct, c.drift_from.c_str(), c.means.fx_n, c.means.fy_n, c.means.fz_n);
    j.push_back({{"file", test.file},
                 {"feed_per_tooth_mm", test.feed_per_tooth_mm},
                 {"spindle_rpm", test.spindle_rpm},
                 {"start_s", c.start_s},
                 {"end_s", c.end_s},
                 {"revolutions", c.revolutions},
                 {"drift_from", c.drift_from},
                 {"drift_n_per_s", c.drift_n_per_s},
                 {"offset_n", c.offset_n},
                 {"fx_mean_n", c.means.fx_n},
                 {"fy_mean_n", c.means.fy_n},
                 {"fz_mean_n", c.means.fz_n}});
    out.push_back(c.means);
  }
  return out;
}

}  // namespace

int run_identify_cutting(const IdentifyArgs& a) {
  const bool records = !a.records.empty() || !a.tests_path.empty();
  if (a.csv_path.empty() == !records || a.teeth == 0 || a.diameter_mm == 0.0 || a.axial_mm == 0.0 ||
      a.radial_mm == 0.0) {
    std::cerr << "robodamp identify cutting: --csv (mean forces) or --records / --tests (force records), and --teeth, "
                 "--diameter-mm, --axial-mm and --radial-mm are required\n";
    return 2;
  }
  identify::CuttingTest t{a.teeth, a.diameter_mm, a.axial_mm, a.radial_mm,
                          a.mode == "up" ? config::MillingMode::kUp : config::MillingMode::kDown};
  identify::CuttingFit f;
  std::vector<identify::MeanForces> samples;
  nlohmann::json record_json;
  try {
    if (a.radial_mm > a.diameter_mm)
      throw std::invalid_argument(
          "--radial-mm = " + config::format_number(a.radial_mm) +
          " mm is out of range: allowed 0 < value <= --diameter-mm = " + config::format_number(a.diameter_mm) + " mm");
    if (records) std::printf("Force records (the force on the %s, axes %s):\n", a.force_on.c_str(), a.axes.c_str());
    samples = records ? means_from_records(a, record_json) : identify::read_mean_forces_csv(a.csv_path);
    f = identify::identify_cutting(samples, t);
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
  std::printf(
      "  R^2 %.6f (x), %.6f (y), %.6f (z); %.6f (x and y together), residual RMS %.4g N, condition number %.3g "
      "(refused above %.0e)\n",
      f.r2_x, f.r2_y, f.r2_z, f.r2_xy, f.residual_rms_n, f.condition_number, identify::kMaxConditionNumber);
  const std::vector<identify::LinearityCheck> linearity = identify::check_linearity(samples, t, f);
  if (samples.size() < 4) std::printf("  linearity in the feed not checked: 4 feeds or more are needed\n");
  nlohmann::json warnings = nlohmann::json::array();
  for (const auto& c : linearity)
    if (!c.linear)
      std::printf("WARNING: %s\n", c.message.c_str()), warnings.push_back({{"axis", std::string(1, c.axis)},
                                                                           {"r2", c.r2},
                                                                           {"linear_up_to_mm", c.linear_up_to_mm},
                                                                           {"message", c.message}});
  if (a.json.given) {
    nlohmann::json j = {{"ktc_n_per_mm2", estimate(f.ktc)},
                        {"krc_n_per_mm2", estimate(f.krc)},
                        {"kac_n_per_mm2", estimate(f.kac)},
                        {"kte_n_per_mm", estimate(f.kte)},
                        {"kre_n_per_mm", estimate(f.kre)},
                        {"kae_n_per_mm", estimate(f.kae)},
                        {"r2_xy", f.r2_xy},
                        {"r2_x", f.r2_x},
                        {"r2_y", f.r2_y},
                        {"r2_z", f.r2_z},
                        {"residual_rms_n", f.residual_rms_n},
                        {"condition_number", f.condition_number},
                        {"samples", f.samples},
                        {"not_linear", warnings}};
    if (records) j["records"] = record_json;
    if (!emit_json(a.json, j.dump(2), "identify")) return 1;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
  }
  if (!a.yaml_path.empty()) {
    std::ofstream y(a.yaml_path);
    y << "material:                 # robodamp identify cutting, " << f.samples << " feeds, R^2 " << f.r2_x << " (x) "
      << f.r2_y << " (y) " << f.r2_z << " (z)" << (warnings.empty() ? "" : "; NOT LINEAR in the feed, see its warnings")
      << "\n"
      << "  name: identified from " << (records ? std::string("force records") : a.csv_path) << "\n"
      << "  kt_n_per_mm2: " << f.ktc.value << "\n  kn_n_per_mm2: " << f.krc.value << "\n  kte_n_per_mm: " << f.kte.value
      << "\n  kne_n_per_mm: " << f.kre.value << "\n  kac_n_per_mm2: " << f.kac.value << "\n"
      << "  # Kae = " << f.kae.value << " N/mm (axial edge; the 2D milling models do not use it)\n";
    std::printf("wrote %s\n", a.yaml_path.c_str());
  }
  return 0;
}

}  // namespace robodamp::apps
