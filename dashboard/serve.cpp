#include "dashboard/serve.hpp"

#include <chrono>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>

#include "config/config.hpp"
#include "config/dashboard_config.hpp"
#include "dashboard/auth.hpp"
#include "dashboard/fleet.hpp"
#include "dashboard/server.hpp"
#include "dashboard/tls.hpp"
#include "rt/signals.hpp"

namespace robodamp::dashboard {

int serve(const ServeRequest& a, std::ostream& out, std::ostream& err) {
  config::DashboardConfig cfg;
  try {
    if (!a.config_path.empty()) cfg = config::load_dashboard_config(a.config_path);
  } catch (const config::ConfigError& e) {
    err << e.what() << '\n';
    return 2;
  }
  if (!a.listen.empty()) cfg.listen_address = a.listen;
  if (a.port) cfg.port = *a.port;
  if (a.domain) cfg.dds.domain_id = *a.domain;
  if (a.transport == "udp_loopback") cfg.dds.transport = config::DdsTransport::kUdpLoopback;
  if (a.transport == "shared_memory") cfg.dds.transport = config::DdsTransport::kSharedMemory;
  if (a.transport == "default") cfg.dds.transport = config::DdsTransport::kDefault;
  if (const std::string why = plain_http_refusal(cfg, a.insecure_http); !why.empty()) {
    err << "robodamp dashboard: " << why << '\n';
    return 2;
  }
  if (!plain_http_refusal(cfg, false).empty())  // served anyway: --insecure-http
    spdlog::warn(
        "dashboard: plain HTTP on {} (--insecure-http): passwords and session tokens cross the network readable",
        cfg.listen_address);
  std::vector<User> users;
  try {
    if (!cfg.credentials.empty()) users = load_users(cfg.credentials);
  } catch (const config::ConfigError& e) {
    err << e.what() << '\n';
    return 2;
  }
  rt::install_shutdown_handlers();
  try {
    Authenticator auth(users, cfg.session_idle_s);
    ActionLog log(cfg.action_log);
    Fleet fleet(cfg.dds, cfg.stale_after_s);
    WebServer server(cfg, fleet, auth, log);
    const int port = server.bind();
    std::jthread serving([&] { server.serve(); });
    struct StopOnExit {
      WebServer& s;
      ~StopOnExit() { s.stop(); }  // before `serving` joins, on every path
    } stop_on_exit{server};
    out << "robodamp dashboard: " << (cfg.tls() ? "https://" : "http://") << cfg.listen_address << ":" << port
        << "/  (DDS domain " << cfg.dds.domain_id << ", " << config::to_string(cfg.dds.transport)
        << (cfg.dds.security ? ", secured" : "") << "; "
        << (auth.anyone_may_act() ? std::to_string(users.size()) + " users from " + cfg.credentials
                                  : std::string("no operator configured: view only"))
        << "; Ctrl-C ends)" << std::endl;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(a.duration_s);
    while (rt::shutdown_signal().load() == 0 && (a.duration_s <= 0.0 || std::chrono::steady_clock::now() < end))
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    server.stop();
    serving.join();
    out << "robodamp dashboard: " << server.health().dump() << std::endl;
  } catch (const std::exception& e) {
    err << "robodamp dashboard: " << e.what() << '\n';
    return 1;
  }
  return 0;
}

}  // namespace robodamp::dashboard
