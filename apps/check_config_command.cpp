// `robodamp check-config FILE`: validate a controller configuration (chain design and the plant's
// physical consistency), a milling job (its structures, controller parts included), a robot model (its
// poses against its joints) or the dashboard's file, every problem at once.
#include <iostream>
#include <memory>

#include <yaml-cpp/yaml.h>

#include "apps/cli.hpp"
#include "config/config.hpp"
#include "config/dashboard_config.hpp"
#include "config/milling_config.hpp"
#include "config/robot_model_config.hpp"
#include "analysis/chain_design.hpp"
#include "milling/structure.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::apps {

namespace {

// What a file is by its top-level keys: a milling job (config/milling/) has `tool`, a robot model
// (config/robots/) `links`, the dashboard's file (docs/dashboard.md) `dashboard`; anything else is a cell's
// configuration.
enum class Kind { kCell, kMillingJob, kRobotModel, kDashboard };
Kind kind_of(const std::string& path) {
  try {
    const YAML::Node n = YAML::LoadFile(path);
    if (!n.IsMap()) return Kind::kCell;
    if (n["tool"].IsDefined()) return Kind::kMillingJob;
    if (n["dashboard"].IsDefined()) return Kind::kDashboard;
    if (n["links"].IsDefined()) return Kind::kRobotModel;
  } catch (const YAML::Exception&) {}
  return Kind::kCell;  // the configuration parser reports a syntax error
}

int check_dashboard(const std::string& path) {
  const auto d = config::load_dashboard_config(path);
  std::cout << path << ": OK (dashboard, " << d.listen_address << ":" << d.port << ", DDS domain " << d.dds.domain_id
            << (d.credentials.empty() ? ", no credentials: nobody may act" : ", credentials " + d.credentials) << ")\n";
  return 0;
}

int check_milling(const std::string& path) {
  const auto job = config::load_milling_config(path);
  for (const auto& s : job.structures) (void)milling::Structure(s, false);
  std::cout << path << ": OK (milling job, " << job.structures.size() << " structure(s), " << job.conditions.size()
            << " condition(s))\n";
  return 0;
}

int check_robot_model(const std::string& path) {
  const auto m = config::load_robot_model(path);
  std::cout << path << ": OK (robot model '" << m.name << "', " << m.links.size() << " links, " << m.joints.size()
            << " joints, " << m.poses.size() << " pose(s))\n";
  return 0;
}

int check_config(const std::string& path) {
  switch (kind_of(path)) {
    case Kind::kMillingJob:
      return check_milling(path);
    case Kind::kRobotModel:
      return check_robot_model(path);
    case Kind::kDashboard:
      return check_dashboard(path);
    case Kind::kCell:
      break;
  }
  const auto cfg = config::load_config_file(path);
  const auto d = analysis::design_chain(cfg);
  if (!cfg.robot.frfs.empty()) (void)sim::build_plant_model(cfg);  // the plant's physical consistency
  std::cout << path << ": OK (" << d.blocks.size() << " blocks, " << d.params.sections.count
            << " second-order sections at " << d.params.fs_hz << " Hz)\n";
  return 0;
}

}  // namespace

void register_check_config(Registry& r) {
  auto path = std::make_shared<std::string>();
  CLI::App* sub = r.add("check-config",
                        "Validate a configuration (a cell's, a milling job, a robot model or the dashboard's) and "
                        "report every problem at once",
                        [path] { return check_config(*path); });
  sub->add_option("file", *path, "Configuration file (YAML)")->required();
}

}  // namespace robodamp::apps
