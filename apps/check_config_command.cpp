// `robodamp check-config FILE`: validate a controller configuration (chain design and the plant's
// physical consistency) or a milling job (its structures, controller parts included), every problem at once.
#include <iostream>
#include <memory>

#include <yaml-cpp/yaml.h>

#include "apps/cli.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "control/chain_design.hpp"
#include "milling/structure.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::apps {

namespace {

// A milling job (config/milling/) has a top-level `tool`; its controller parts are loaded and checked too.
bool is_milling_job(const std::string& path) {
  try {
    return YAML::LoadFile(path)["tool"].IsDefined();
  } catch (const YAML::Exception&) {
    return false;  // the configuration parser reports the syntax error
  }
}

int check_milling(const std::string& path) {
  const auto job = config::load_milling_config(path);
  for (const auto& s : job.structures) (void)milling::Structure(s, false);
  std::cout << path << ": OK (milling job, " << job.structures.size() << " structure(s), " << job.conditions.size()
            << " condition(s))\n";
  return 0;
}

int check_config(const std::string& path) {
  if (is_milling_job(path)) return check_milling(path);
  const auto cfg = config::load_config_file(path);
  const auto d = control::design_chain(cfg);
  if (!cfg.robot.frfs.empty()) (void)sim::build_plant_model(cfg);  // the plant's physical consistency
  std::cout << path << ": OK (" << d.blocks.size() << " blocks, " << d.params.sections.count
            << " second-order sections at " << d.params.fs_hz << " Hz)\n";
  return 0;
}

}  // namespace

void register_check_config(Registry& r) {
  auto path = std::make_shared<std::string>();
  CLI::App* sub = r.add("check-config", "Validate a configuration (controller or milling job) and report every problem at once",
                        [path] { return check_config(*path); });
  sub->add_option("file", *path, "Configuration file (YAML)")->required();
}

}  // namespace robodamp::apps
