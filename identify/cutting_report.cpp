#include "identify/cutting_report.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "fields/printf.hpp"

namespace robodamp::identify {

namespace {

namespace fs = std::filesystem;
using fields::printf_string;

nlohmann::json estimate(const Estimate& e) { return {{"value", e.value}, {"ci95", e.ci95}}; }

}  // namespace

std::vector<RecordTest> record_tests(const std::string& tests_path, const std::vector<std::string>& records,
                                     const std::vector<double>& feeds_mm, double rpm) {
  if (!tests_path.empty()) {
    if (!records.empty() || !feeds_mm.empty())
      throw std::invalid_argument("--tests names the records and their feeds: leave out --records and --feeds-mm");
    return read_record_tests(tests_path);
  }
  std::vector<std::string> files;
  for (const auto& r : records) {
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
  if (files.size() != feeds_mm.size() || rpm <= 0.0)
    throw std::invalid_argument(
        std::to_string(files.size()) + " records and " + std::to_string(feeds_mm.size()) +
        " feeds: give one --feeds-mm value per record (in name order) and --rpm, or a --tests table "
        "(file, feed_per_tooth_mm, spindle_rpm)");
  std::vector<RecordTest> out;
  for (std::size_t i = 0; i < files.size(); ++i) out.push_back({files[i], feeds_mm[i], rpm});
  return out;
}

RecordMeans means_from_records(const std::vector<RecordTest>& tests, const RecordSettings& s,
                               const std::function<void(const std::string&)>& line) {
  RecordMeans out;
  out.json = nlohmann::json::array();
  for (const auto& test : tests) {
    const ForceRecord r = read_force_record(test.file);
    const SteadyCut c = steady_cut(r, test.spindle_rpm, test.feed_per_tooth_mm, s);
    line(printf_string(
        "  %s: %.4g mm/tooth at %.0f rpm: steady %.3f-%.3f s (%d whole revolutions of %d cutting; means within %.2f "
        "%%), "
        "drift from %s; on the tool Fx %.2f Fy %.2f Fz %.2f N\n",
        test.file.c_str(), test.feed_per_tooth_mm, test.spindle_rpm, c.start_s, c.end_s, c.revolutions,
        c.cutting_revolutions, c.spread_pct, c.drift_from.c_str(), c.means.fx_n, c.means.fy_n, c.means.fz_n));
    out.json.push_back({{"file", test.file},
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
    out.means.push_back(c.means);
  }
  return out;
}

CuttingReport cutting_report(const CuttingFit& f, const std::vector<MeanForces>& samples, const CuttingTest& t,
                             const std::string& mode, const std::string& source, const nlohmann::json& records) {
  CuttingReport r;
  std::string& text = r.text;
  text = printf_string(
      "Cutting coefficients from %d feeds (%d teeth, %.3g mm, %.3g mm axial, %.3g mm radial, %s milling):\n", f.samples,
      t.teeth, t.diameter_mm, t.axial_mm, t.radial_mm, mode.c_str());
  auto line = [&text](const char* name, const Estimate& e, const char* unit) {
    text += printf_string("  %-4s %10.3f +- %.3f %s (95 %%)\n", name, e.value, e.ci95, unit);
  };
  line("Ktc", f.ktc, "N/mm^2"), line("Krc", f.krc, "N/mm^2"), line("Kac", f.kac, "N/mm^2");
  line("Kte", f.kte, "N/mm"), line("Kre", f.kre, "N/mm"), line("Kae", f.kae, "N/mm");
  text += printf_string(
      "  R^2 %.6f (x), %.6f (y), %.6f (z); %.6f (x and y together), residual RMS %.4g N, condition number %.3g "
      "(refused above %.0e)\n",
      f.r2_x, f.r2_y, f.r2_z, f.r2_xy, f.residual_rms_n, f.condition_number, kMaxConditionNumber);
  const std::vector<LinearityCheck> linearity = check_linearity(samples, t, f);
  if (samples.size() < 4) text += "  linearity in the feed not checked: 4 feeds or more are needed\n";
  nlohmann::json warnings = nlohmann::json::array();
  for (const auto& c : linearity)
    if (!c.linear) {
      text += "WARNING: " + c.message + "\n";
      warnings.push_back({{"axis", std::string(1, c.axis)},
                          {"r2", c.r2},
                          {"linear_up_to_mm", c.linear_up_to_mm},
                          {"message", c.message}});
    }
  r.json = {{"ktc_n_per_mm2", estimate(f.ktc)},
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
  if (!records.is_null()) r.json["records"] = records;
  std::ostringstream y;
  y << "material:                 # robodamp identify cutting, " << f.samples << " feeds, R^2 " << f.r2_x << " (x) "
    << f.r2_y << " (y) " << f.r2_z << " (z)" << (warnings.empty() ? "" : "; NOT LINEAR in the feed, see its warnings")
    << "\n"
    << "  name: identified from " << source << "\n"
    << "  kt_n_per_mm2: " << f.ktc.value << "\n  kn_n_per_mm2: " << f.krc.value << "\n  kte_n_per_mm: " << f.kte.value
    << "\n  kne_n_per_mm: " << f.kre.value << "\n  kac_n_per_mm2: " << f.kac.value << "\n"
    << "  # Kae = " << f.kae.value << " N/mm (axial edge; the 2D milling models do not use it)\n";
  r.yaml = y.str();
  return r;
}

}  // namespace robodamp::identify
