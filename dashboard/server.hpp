// The dashboard's web server (docs/dashboard.md), on cpp-httplib: the page (embedded HTML, script and style;
// dygraphs from Debian's libjs-dygraphs), the fleet and a cell as JSON, a server-sent event stream per open
// page (urgent changes at once, the rest at most 10 times a second), login and logout, and operator actions
// that become supervised parameter requests to the cell. Every refused or malformed request is answered
// with a status and a reason and counted; the server's threads never touch the cells' real-time loops.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "config/dashboard_config.hpp"
#include "dashboard/auth.hpp"
#include "dashboard/fleet.hpp"

namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace robodamp::dashboard {

struct ServerCounters {
  std::uint64_t requests{0}, client_errors{0}, server_errors{0}, too_large{0}, not_found{0};
  std::uint64_t unauthenticated{0}, forbidden{0}, actions{0}, actions_accepted{0};
  std::uint64_t streams_opened{0}, streams_refused{0}, events{0};
};

class WebServer {
 public:
  WebServer(const config::DashboardConfig& cfg, Fleet& fleet, Authenticator& auth, ActionLog& log);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // Binds cfg.listen_address:cfg.port (0: any free port); the port bound. Throws std::runtime_error.
  int bind();
  // Serves until stop() (blocks).
  void serve();
  void stop();
  [[nodiscard]] ServerCounters counters() const;
  [[nodiscard]] nlohmann::json health() const;

 private:
  void routes();
  void action(const httplib::Request& req, httplib::Response& res);
  void events(const httplib::Request& req, httplib::Response& res);
  [[nodiscard]] std::optional<Session> session_of(const httplib::Request& req);

  config::DashboardConfig cfg_;
  Fleet& fleet_;
  Authenticator& auth_;
  ActionLog& log_;
  std::unique_ptr<httplib::Server> http_;
  std::atomic<bool> stopping_{false};
  std::atomic<int> streams_{0};
  struct Atomics;
  std::unique_ptr<Atomics> n_;
};

}  // namespace robodamp::dashboard
