// What a DDS client of the cell (`robodamp monitor`, `robodamp request`) joins: the domain, the transport, its
// own security identity and the cell it speaks to, from its options or from a configuration's dds section.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "config/config.hpp"

namespace robodamp::dds {

struct ClientOptions {
  int domain_id{0};
  config::DdsTransport transport{config::DdsTransport::kDefault};
  double duration_s{0.0};  // monitor: 0 = until Ctrl-C; request: how long to wait for the loop and the reply
  std::optional<config::DdsSecurityConfig> security;  // the client's own identity (the --config's dds.security)
  std::string cell;  // --cell, else the --config's cell.name (its host's name when unset), else empty
};

// The options as given: each one given overrides the configuration's.
struct ClientRequest {
  ClientOptions options;
  std::optional<int> domain;
  std::string transport{"default"};  // default, udp_loopback or shared_memory
  std::string config_path;           // empty: no configuration
  std::string cell;
};

// The options with the configuration's dds section applied; nothing (after writing why to `err`) on a bad file.
[[nodiscard]] std::optional<ClientOptions> resolve(const ClientRequest& a, std::ostream& err);

}  // namespace robodamp::dds
