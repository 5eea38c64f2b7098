#include "runtime/speed_sets.hpp"

#include <cstdio>
#include <string>

namespace robodamp::runtime {

void own_speed_bands(control::ControllerParams& p, std::size_t own_index) {
  for (std::size_t i = 0; i < p.speed_band_count; ++i)
    if (p.speed_bands[i].set == 0) p.speed_bands[i].set = own_index;
}

void check_speed_bands(const rt::Supervisor& sup, const std::vector<config::Config>& set_configs) {
  const auto& sets = sup.parameter_sets();
  for (std::size_t s = 0; s < sets.size() && s < set_configs.size(); ++s) {
    const control::ControllerParams& p = sets[s].params;
    const config::Config& c = set_configs[s];
    const double limit = c.supervision.max_gain_fraction * sets[s].max_stable_gain_ns_per_m;
    for (std::size_t b = 0; b < p.speed_band_count; ++b) {
      if (p.speed_bands[b].set != s) continue;  // checked by the set it runs
      char why[200];
      std::snprintf(why, sizeof why,
                    "supervision.max_gain_fraction = %g x the analysed maximum stable K %.1f N s/m of its controller",
                    c.supervision.max_gain_fraction, sets[s].max_stable_gain_ns_per_m);
      if (auto problem = config::gain_request_problem(p.speed_bands[b].gain_ns_per_m, limit, why))
        throw config::ConfigError(config::located(
            {{c.source, {}, "controller.speed_schedule.bands[" + std::to_string(b) + "].gain_ns_per_m", *problem}},
            c.yaml_text));
    }
  }
  for (std::size_t s = 0; s < sets.size(); ++s)  // a band naming a set that was never added
    for (std::size_t b = 0; b < sets[s].params.speed_band_count; ++b)
      if (sets[s].params.speed_bands[b].set >= sets.size())
        throw config::ConfigError({{set_configs.at(s).source,
                                    {},
                                    "controller.speed_schedule.bands[" + std::to_string(b) + "].controller",
                                    "names a controller this cell does not have"}});
}

}  // namespace robodamp::runtime
