#include "dds/client_options.hpp"

namespace robodamp::dds {

std::optional<ClientOptions> resolve(const ClientRequest& a, std::ostream& err) {
  ClientOptions o = a.options;
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
      err << e.what() << '\n';
      return std::nullopt;
    }
  }
  if (!a.cell.empty()) o.cell = a.cell;
  if (a.domain) o.domain_id = *a.domain;
  if (a.transport == "udp_loopback") o.transport = config::DdsTransport::kUdpLoopback;
  if (a.transport == "shared_memory") o.transport = config::DdsTransport::kSharedMemory;
  return o;
}

}  // namespace robodamp::dds
