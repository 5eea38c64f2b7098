#include "apps/dds_client.hpp"

#include <iostream>

namespace robodamp::apps {

void add_dds_options(Registry& r, CLI::App* sub, DdsClientArgs& a) {
  r.whole_number(sub, "--domain", a.domain, {"(DDS domain id)", 0, 232},
                 "DDS domain (default: dds.domain_id of --config, else 0)");
  sub->add_option("--config", a.config_path, "Take the domain and transport from this configuration's dds section")
      ->check(CLI::ExistingFile);
  sub->add_option("--transport", a.transport, "default, udp_loopback or shared_memory")
      ->check(CLI::IsMember({"default", "udp_loopback", "shared_memory"}));
  sub->add_option("--cell", a.cell,
                  "The cell (its cell.name; default: the --config's cell.name, or with no --config, "
                  "for a request this host's name)")
      ->check([](const std::string& v) {
        const std::string p = config::cell_name_problem(v);
        return p.empty() ? std::string() : "--cell = \"" + v.substr(0, 64) + "\" " + p;
      });
}

std::optional<DdsClientOptions> resolve(const DdsClientArgs& a) {
  DdsClientOptions o = a.options;
  if (!a.config_path.empty()) {
    try {
      const auto cfg = config::load_config_file(a.config_path);
      if (cfg.dds) {
        o.domain_id = cfg.dds->domain_id;
        o.transport = cfg.dds->transport;
        o.security = cfg.dds->security;
      }
      o.cell = config::cell_name(cfg.cell);
    } catch (const config::ConfigError& e) {
      std::cerr << e.what() << '\n';
      return std::nullopt;
    }
  }
  if (!a.cell.empty()) o.cell = a.cell;
  if (a.domain) o.domain_id = *a.domain;
  if (a.transport == "udp_loopback") o.transport = config::DdsTransport::kUdpLoopback;
  if (a.transport == "shared_memory") o.transport = config::DdsTransport::kSharedMemory;
  return o;
}

}  // namespace robodamp::apps
