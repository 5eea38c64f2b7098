// `robodamp dashboard`: the dashboard's configuration with the command line's options applied, checked (plain
// HTTP only where it is safe or asked for), and served until Ctrl-C or the duration (docs/dashboard.md).
#pragma once

#include <optional>
#include <ostream>
#include <string>

namespace robodamp::dashboard {

// The options as given; each one given overrides the configuration's.
struct ServeRequest {
  std::string config_path;  // empty: the defaults
  std::string listen;
  std::optional<int> port, domain;
  std::string transport;   // default, udp_loopback, shared_memory or empty: the configuration's
  double duration_s{0.0};  // 0: until Ctrl-C
  bool insecure_http{false};
};

// The address served and, at the end, the server's health on `out`. 0 served to the end, 2 a configuration or
// credentials file refused (the reason on `err`), 1 the server failed.
[[nodiscard]] int serve(const ServeRequest& a, std::ostream& out, std::ostream& err);

}  // namespace robodamp::dashboard
