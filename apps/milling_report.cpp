#include "apps/milling_report.hpp"

#include <iostream>

namespace robodamp::apps {

using nlohmann::json;

namespace {

int finish(const json& report, const MillingOptions& o, const std::string& command, const std::string& table,
           std::string (*plot)(const json&, const std::string&)) {
  const std::string target = plot_file(o.plot_dir, o.plot_path, command + ".png");
  return print_report(
      report.dump(2), o.json, command, table, target, [&] { return plot(report, target); }, target);
}

}  // namespace

milling::StudyOptions study_options(const MillingOptions& o) {
  return {o.structure, o.controller_path, o.damped, o.rpm, o.method};
}

json lobes_report(const config::MillingConfig& cfg, const MillingOptions& o) {
  return milling::lobes_report(cfg, study_options(o), [](const std::string& line) { std::cerr << line; });
}

json sle_report(const config::MillingConfig& cfg, const MillingOptions& o) {
  return milling::sle_report(cfg, study_options(o));
}

int print_lobes(const json& r, const MillingOptions& o) {
  return finish(r, o, "lobes", milling::lobes_table(r), milling::plot_lobes);
}

int print_sle(const json& r, const MillingOptions& o) {
  return finish(r, o, "sle", milling::sle_table(r), milling::plot_sle);
}

void add_milling_options(Registry& r, CLI::App* sub, MillingOptions& o, const std::string& command) {
  r.job(sub, o.job_path);
  sub->add_option("--structure", o.structure, "Which of the job's structures (default: its `structure`)");
  r.json(sub, o.json, "The report (every speed, the limits and their methods)");
  r.plot_dir(sub, o.plot_dir, command + ".png");
  r.deprecated(sub->add_option("--plot", o.plot_path, "Write the plot to this file (PNG)"), "--plot-dir DIR");
  sub->add_flag("--damped", o.damped, "Also with the damping controller's loop closed, overlaid");
  sub->add_option("--controller", o.controller_path,
                  "Damping configuration to use instead of the job's (compare compensators)")
      ->check(CLI::ExistingFile);
}

}  // namespace robodamp::apps
