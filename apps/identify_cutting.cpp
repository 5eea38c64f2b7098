// `robodamp identify cutting`: cutting coefficients of a flat end mill from mean forces (--csv) or from the
// raw force records of the tests (--records: each record's steady cut found, its drift removed, its mean
// taken), with 95 % intervals, R^2 per axis and a warning where a force is not linear in the feed
// (identify/cutting_report.hpp). docs/identification.md.
#include <cstdio>
#include <fstream>
#include <iostream>

#include "apps/identify_command.hpp"
#include "identify/cutting_report.hpp"

namespace robodamp::apps {

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
    if (records) {
      std::printf("Force records (the force on the %s, axes %s):\n", a.force_on.c_str(), a.axes.c_str());
      identify::RecordSettings s;
      s.axes = identify::parse_axes(a.axes);
      s.force_on_workpiece = a.force_on == "workpiece";
      identify::RecordMeans m =
          identify::means_from_records(identify::record_tests(a.tests_path, a.records, a.feeds_mm, a.rpm), s,
                                       [](const std::string& line) { std::fputs(line.c_str(), stdout); });
      samples = std::move(m.means), record_json = std::move(m.json);
    } else {
      samples = identify::read_mean_forces_csv(a.csv_path);
    }
    f = identify::identify_cutting(samples, t);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify cutting: " << e.what() << '\n';
    return 2;
  }
  const identify::CuttingReport r =
      identify::cutting_report(f, samples, t, a.mode, records ? std::string("force records") : a.csv_path, record_json);
  if (!print_identified(a, r.text, r.json, r.yaml)) return 1;
  return 0;
}

}  // namespace robodamp::apps
