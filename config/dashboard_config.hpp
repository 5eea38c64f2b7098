// The operator's dashboard (`robodamp dashboard`, docs/dashboard.md): where it serves, who may act, where
// actions are logged, and the DDS domain it joins (with the operator identity when the domain is secured).
// Its own file, read with the same checks and wording as a cell's configuration.
#pragma once

#include <optional>
#include <string>

#include "config/supervisory_config.hpp"

namespace robodamp::config {

struct DashboardConfig {
  std::string source;
  std::string listen_address{"127.0.0.1"};  // loopback unless the file says otherwise
  int port{8080};                           // 0: any free port (printed)
  std::string credentials;                  // users file (robodamp dashboard-user writes it); empty: nobody may act
  std::string action_log;                   // every operator action appended here; empty: <credentials>.actions.log
  // HTTPS: the server's certificate (PEM, with its chain) and private key; both or neither. Without them the
  // page is plain HTTP, which `robodamp dashboard` serves only on a loopback address unless told otherwise
  // (passwords and session tokens would cross the network readable). `robodamp dashboard-cert` makes a
  // self-signed pair for a first install; the cell's PKI (dds.security) can issue one.
  std::string tls_certificate;
  std::string tls_private_key;
  double session_idle_s{8 * 3600.0};  // a session ends after this long unused
  double stale_after_s{2.0};          // a cell not heard from for this long shows "no contact"
  double reply_timeout_s{5.0};        // an action waits this long for the cell's reply
  int max_event_streams{16};          // open live pages at once
  std::size_t max_body_bytes{4096};   // request bodies beyond this are refused (413)
  DdsConfig dds;                      // domain, transport, security (the operator identity)
  [[nodiscard]] bool tls() const { return !tls_certificate.empty(); }
};

// Throws ConfigError with every problem (file, line, key, value, unit, allowed range).
[[nodiscard]] DashboardConfig parse_dashboard_config(const std::string& yaml_text, const std::string& source_name);
[[nodiscard]] DashboardConfig load_dashboard_config(const std::string& path);

}  // namespace robodamp::config
