// `robodamp filters`: each block of the damping chain and the whole chain at a frequency, analog and digital
// (analysis/chain_report.hpp).
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "analysis/chain_report.hpp"
#include "apps/cli.hpp"

namespace robodamp::apps {

namespace {

struct FiltersArgs {
  std::string config_path{default_cell_config()};
  std::optional<double> freq_hz;  // default: the chain's match frequency
  JsonOut json;
  std::string plot_dir, plot;
};

int run_filters(const FiltersArgs& a) {
  const analysis::ChainDesign d = analysis::design_chain(config::load_config_file(a.config_path));
  // The frequency's upper bound depends on the configuration's loop rate, so it is checked here.
  const double freq_hz = a.freq_hz.value_or(d.match_freq_hz);
  if (auto p = config::range_problem("--freq", freq_hz,
                                     {"Hz", 0.0, 0.5 * d.params.fs_hz, true, true, "below Nyquist of loop.rate_hz"})) {
    std::cerr << "robodamp filters: " << *p << '\n';
    return 2;
  }
  const auto report = analysis::filters_report(d, freq_hz);
  const std::string target = plot_file(a.plot_dir, a.plot, "filters.png");
  return print_report(
      report.dump(2), a.json, "filters", analysis::filters_table(report), target,
      [&] { return analysis::plot_filters(d, target); }, target);
}

}  // namespace

void register_filters(Registry& r) {
  auto a = std::make_shared<FiltersArgs>();
  CLI::App* sub = r.add("filters", "Magnitude and phase of each block and the chain, analog and digital",
                        [a] { return run_filters(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  r.number(sub, "--freq", a->freq_hz, {"Hz", 0.0, 1e6, true, false, "and below Nyquist of loop.rate_hz"},
           "Frequency in Hz (default: the chain's match frequency, where it is designed to damp)");
  r.json(sub, a->json, "The blocks' and the chain's magnitude and phase");
  r.plot_dir(sub, a->plot_dir, "filters.png, the Bode diagram of the blocks and the chain,");
  r.deprecated(sub->add_option("--plot", a->plot, "Write the Bode diagram to this file (PNG)"), "--plot-dir DIR");
}

}  // namespace robodamp::apps
