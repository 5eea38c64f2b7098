// What `robodamp monitor` and `robodamp request` share: the DDS domain and transport, from the options
// or from a configuration's dds section.
#pragma once

#include <optional>
#include <string>

#include "apps/cli.hpp"
#include "config/config.hpp"

namespace robodamp::apps {

struct DdsClientOptions {
  int domain_id{0};
  config::DdsTransport transport{config::DdsTransport::kDefault};
  double duration_s{0.0};  // monitor: 0 = until Ctrl-C; request: how long to wait for the loop and the reply
  std::optional<config::DdsSecurityConfig> security;  // the client's own identity (the --config's dds.security)
  std::string cell;  // --cell, else the --config's cell.name (its host's name when unset), else empty
};

struct DdsClientArgs {
  DdsClientOptions options;
  std::optional<int> domain;
  std::string transport{"default"};
  std::string config_path;
  std::string cell;
};

void add_dds_options(Registry& r, CLI::App* sub, DdsClientArgs& a);
// The options with the configuration's dds section applied; nothing (after printing why) on a bad file.
[[nodiscard]] std::optional<DdsClientOptions> resolve(const DdsClientArgs& a);

}  // namespace robodamp::apps
