#include "apps/plant_command.hpp"

#include <fstream>
#include <iostream>

#include <spdlog/spdlog.h>

#include "apps/run_command.hpp"
#include "hil/plant_emulator.hpp"
#include "rt/signals.hpp"

namespace robodamp::apps {

int run_plant(const PlantOptions& o) {
  const auto loaded = load_config_or_report(o.config_path);
  if (!loaded) return 2;
  const config::Config& cfg = *loaded;
  hil::EmulatorOptions eo;
  eo.pacing = o.pacing;
  eo.max_duration_s = o.duration_s;
  eo.impacts = o.impacts;
  eo.impact_location = o.impact_location;
  for (const auto& item : o.mounting_schedule) {
    const auto colon = item.find(':');
    double t = -1.0;
    try {
      t = colon == std::string::npos ? -1.0 : std::stod(item.substr(0, colon));
    } catch (const std::exception&) {
    }
    const std::string m = colon == std::string::npos ? "" : item.substr(colon + 1);
    if (!(t >= 0.0) || (m != "horizontal" && m != "vertical")) {
      std::cerr << "--mounting '" << item << "': expected TIME_S:horizontal or TIME_S:vertical with TIME_S >= 0 s\n";
      return 2;
    }
    eo.mounting_schedule.emplace_back(t, m == "vertical" ? config::Mounting::kVertical : config::Mounting::kHorizontal);
  }
  rt::install_shutdown_handlers();
  eo.stop_flag = &rt::shutdown_signal();
  try {
    const hil::EmulatorReport r = hil::run_emulator(cfg, eo);
    std::cout << hil::report_text(r);
    if (!o.json_path.empty()) {
      std::ofstream out(o.json_path);
      out << hil::report_json(r).dump(2) << '\n';
      if (!out) {
        std::cerr << "--json " << o.json_path << ": cannot write\n";
        return 1;
      }
    }
    return r.records_planned > 0 && !r.campaign_complete ? 1 : 0;
  } catch (const std::exception& e) {
    std::cerr << "robodamp plant: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace robodamp::apps
