// The dashboard over HTTPS (docs/dashboard.md, "HTTPS"): a self-signed certificate and key for a first
// install (`robodamp dashboard-cert`), and the rule for plain HTTP: only on a loopback address, or when the
// operator says in so many words that passwords and session tokens may cross the network readable.
#pragma once

#include <string>
#include <vector>

#include "config/dashboard_config.hpp"

namespace robodamp::dashboard {

// An ECDSA P-256 key and a self-signed X.509 v3 certificate for it (SHA-256; subjectAltName: each host, an
// IP address as IP, else a DNS name; serverAuth; valid from now for `days`). The key file is written mode
// 0600. Refuses (std::runtime_error, naming the file) to overwrite either file unless `overwrite`.
struct SelfSignedRequest {
  std::vector<std::string> hosts{"localhost", "127.0.0.1"};
  int days{825};
  bool overwrite{false};
};
void write_self_signed(const std::string& certificate_path, const std::string& key_path, const SelfSignedRequest& r);

// 127.0.0.0/8, ::1 and "localhost".
[[nodiscard]] bool is_loopback_address(const std::string& address);

// Why the dashboard must not serve as configured (empty: it may): plain HTTP on an address other hosts
// reach, unless `plain_http_allowed` (the command line's --insecure-http).
[[nodiscard]] std::string plain_http_refusal(const config::DashboardConfig& cfg, bool plain_http_allowed);

}  // namespace robodamp::dashboard
