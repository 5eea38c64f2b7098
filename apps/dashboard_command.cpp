// `robodamp dashboard`: the operator's web page for every cell on the DDS domain (docs/dashboard.md), and
// `robodamp dashboard-user`: adds a user to the credentials file it names.
#include <iostream>
#include <memory>
#include <string>

#include "apps/cli.hpp"
#include "dashboard/auth.hpp"
#include "dashboard/serve.hpp"
#include "dashboard/tls.hpp"

namespace robodamp::apps {

namespace {

using DashboardArgs = dashboard::ServeRequest;

struct CertArgs {
  std::string certificate, key;
  dashboard::SelfSignedRequest request;
};

int run_dashboard_cert(const CertArgs& a) {
  try {
    dashboard::write_self_signed(a.certificate, a.key, a.request);
  } catch (const std::exception& e) {
    std::cerr << "robodamp dashboard-cert: " << e.what() << '\n';
    return 2;
  }
  std::string hosts;
  for (const auto& h : a.request.hosts) hosts += (hosts.empty() ? "" : ", ") + h;
  std::cout << "robodamp dashboard-cert: " << a.certificate << " (self-signed for " << hosts << ", " << a.request.days
            << " days) and its key " << a.key << " (mode 0600); in the dashboard's configuration:\n"
            << "  dashboard:\n    tls_certificate: " << a.certificate << "\n    tls_private_key: " << a.key << '\n';
  return 0;
}

int run_dashboard_user(const std::string& file, const std::string& user, const std::string& role) {
  if (const std::string p = dashboard::user_name_problem(user); !p.empty()) {
    std::cerr << "robodamp dashboard-user: --user = '" << user << "' " << p << '\n';
    return 2;
  }
  std::string password;
  if (!std::getline(std::cin, password) || password.size() < 8) {
    std::cerr
        << "robodamp dashboard-user: give the password on the first line of standard input (at least 8 characters)\n";
    return 2;
  }
  try {
    dashboard::save_user(file, {user, role == "operator" ? dashboard::Role::kOperator : dashboard::Role::kObserver,
                                dashboard::hash_password(password)});
  } catch (const std::exception& e) {
    std::cerr << "robodamp dashboard-user: " << e.what() << '\n';
    return 1;
  }
  std::cout << "robodamp dashboard-user: " << user << " (" << role << ") written to " << file << '\n';
  return 0;
}

}  // namespace

void register_dashboard(Registry& r) {
  auto a = std::make_shared<DashboardArgs>();
  CLI::App* sub =
      r.add("dashboard",
            "Web page for every robodamp cell on the DDS domain: fleet tiles, a cell's live plots and counters, "
            "operator actions after a login (docs/dashboard.md)",
            [a] { return dashboard::serve(*a, std::cout, std::cerr); });
  sub->add_option("--config", a->config_path, "Dashboard configuration (dashboard and dds sections; docs/dashboard.md)")
      ->check(CLI::ExistingFile);
  sub->add_option("--listen", a->listen, "Address to serve on (default dashboard.listen_address, else 127.0.0.1)");
  r.whole_number(sub, "--port", a->port, {"(TCP port)", 0, 65535, false, false, "0 = any free port"},
                 "TCP port (default dashboard.port, else 8080; 0 = any free one, printed)");
  r.whole_number(sub, "--domain", a->domain, {"(DDS domain id)", 0, 232}, "DDS domain (default dds.domain_id, else 0)");
  sub->add_option("--transport", a->transport, "default, udp_loopback or shared_memory")
      ->check(CLI::IsMember({"default", "udp_loopback", "shared_memory"}));
  r.number(sub, "--duration", a->duration_s, {"s", 0.0, 1e7, false, false, "0 = until Ctrl-C"}, "Stop after S seconds");
  sub->add_flag("--insecure-http", a->insecure_http,
                "Serve plain HTTP on an address other hosts reach (without dashboard.tls_*): passwords and session "
                "tokens then cross the network readable");

  auto cert = std::make_shared<CertArgs>();
  CLI::App* c = r.add("dashboard-cert",
                      "Make a self-signed certificate and key for the dashboard's HTTPS (ECDSA P-256; for a first "
                      "install: browsers warn until it is trusted; the cell's PKI can issue a real one)",
                      [cert] { return run_dashboard_cert(*cert); });
  c->add_option("--cert", cert->certificate, "The certificate file to write (PEM)")->required();
  c->add_option("--key", cert->key, "The private key file to write (PEM, mode 0600)")->required();
  c->add_option("--host", cert->request.hosts,
                "The names and addresses the dashboard is reached by (default localhost 127.0.0.1)");
  r.whole_number(c, "--days", cert->request.days, {"days", 1, 3650}, "Valid for this many days (default 825)");
  c->add_flag("--overwrite", cert->request.overwrite, "Replace existing files");

  auto file = std::make_shared<std::string>();
  auto user = std::make_shared<std::string>();
  auto role = std::make_shared<std::string>("observer");
  CLI::App* u = r.add("dashboard-user",
                      "Add or replace a dashboard user in a credentials file (password on the first line of stdin; "
                      "PBKDF2-HMAC-SHA256, file mode 0600)",
                      [file, user, role] { return run_dashboard_user(*file, *user, *role); });
  u->add_option("--file", *file, "The credentials file (created when missing)")->required();
  u->add_option("--user", *user, "User name (letters, digits, '-', '_', '.')")->required();
  u->add_option("--role", *role, "operator (may act) or observer (sees only); default observer")
      ->check(CLI::IsMember({"operator", "observer"}));
}

}  // namespace robodamp::apps
