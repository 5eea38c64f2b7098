#include "dashboard/server.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <httplib.h>
#include <spdlog/spdlog.h>

#include "dashboard/web_assets.hpp"

namespace robodamp::dashboard {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kDygraphsDir = "/usr/share/javascript/dygraphs";  // Debian's libjs-dygraphs

// JSON text that never throws on bytes that are not UTF-8 (a reason from a cell, a name in a request).
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

void reply(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(dump(body), "application/json");
}

void refuse(httplib::Response& res, int status, const std::string& why) { reply(res, status, {{"error", why}}); }

struct ActionKind {
  const char* name;
  dds::RequestKind kind;
  bool needs_value;
};
constexpr ActionKind kActions[] = {{"arm", dds::RequestKind::kEnable, false},
                                   {"disarm", dds::RequestKind::kEnable, false},
                                   {"reset", dds::RequestKind::kResetFault, false},
                                   {"gain", dds::RequestKind::kSetGain, true},
                                   {"set", dds::RequestKind::kSelectParameterSet, true},
                                   {"spindle", dds::RequestKind::kSetSpindleRpm, true}};

// HTTPS with the configured certificate and key, else plain HTTP (which the command allows only on loopback
// or when told: dashboard/tls.hpp).
std::unique_ptr<httplib::Server> make_http(const config::DashboardConfig& cfg) {
  if (!cfg.tls()) return std::make_unique<httplib::Server>();
  auto https = std::make_unique<httplib::SSLServer>(cfg.tls_certificate.c_str(), cfg.tls_private_key.c_str());
  if (!https->is_valid())
    throw std::runtime_error("dashboard: cannot serve HTTPS with dashboard.tls_certificate '" + cfg.tls_certificate +
                             "' and dashboard.tls_private_key '" + cfg.tls_private_key +
                             "' (not PEM, not readable, or the key is not the certificate's)");
  return https;
}

// On every response: the page's script, style and data come from this server only and it is never framed
// (clickjacking an operator's arm button); no type sniffing; no referrer. Style allows inline attributes:
// dygraphs colours its legend with them. Authenticated data is never cached (reply(): no-store).
httplib::Headers secure_headers() {
  return {{"Content-Security-Policy",
           "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
           "connect-src 'self'; object-src 'none'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"},
          {"X-Content-Type-Options", "nosniff"},
          {"X-Frame-Options", "DENY"},
          {"Referrer-Policy", "no-referrer"}};
}

}  // namespace

struct WebServer::Atomics {
  std::atomic<std::uint64_t> requests{0}, client_errors{0}, server_errors{0}, too_large{0}, not_found{0};
  std::atomic<std::uint64_t> unauthenticated{0}, forbidden{0}, actions{0}, actions_accepted{0};
  std::atomic<std::uint64_t> streams_opened{0}, streams_refused{0}, events{0};
};

WebServer::WebServer(const config::DashboardConfig& cfg, Fleet& fleet, Authenticator& auth, ActionLog& log)
    : cfg_(cfg), fleet_(fleet), auth_(auth), log_(log), http_(make_http(cfg)), n_(std::make_unique<Atomics>()) {
  http_->set_default_headers(secure_headers());
  http_->set_payload_max_length(cfg_.max_body_bytes);
  http_->set_read_timeout(5, 0);
  http_->set_write_timeout(5, 0);
  const std::size_t threads = static_cast<std::size_t>(cfg_.max_event_streams) + 8;  // streams hold a thread each
  http_->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  http_->set_logger([this](const httplib::Request&, const httplib::Response& res) {
    ++n_->requests;
    if (res.status == 413) ++n_->too_large;
    if (res.status == 404) ++n_->not_found;
    if (res.status >= 400 && res.status < 500) ++n_->client_errors;
    if (res.status >= 500) ++n_->server_errors;
  });
  http_->set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "internal error";
    try {
      if (ep) std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {}
    refuse(res, 500, what);
  });
  http_->set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty()) {
      res.set_header("Cache-Control", "no-store");
      res.set_content(dump(json{{"error", "HTTP " + std::to_string(res.status)}}), "application/json");
    }
  });
  routes();
}

WebServer::~WebServer() { stop(); }

int WebServer::bind() {
  const int port = cfg_.port == 0 ? http_->bind_to_any_port(cfg_.listen_address)
                                  : (http_->bind_to_port(cfg_.listen_address, cfg_.port) ? cfg_.port : -1);
  if (port <= 0)
    throw std::runtime_error("dashboard: cannot listen on " + cfg_.listen_address + ":" + std::to_string(cfg_.port) +
                             " (dashboard.listen_address, dashboard.port: in use, or not an address of this host)");
  return port;
}

void WebServer::serve() { http_->listen_after_bind(); }

void WebServer::stop() {
  stopping_ = true;
  if (http_) http_->stop();
}

std::optional<Session> WebServer::session_of(const httplib::Request& req) {
  const std::string h = req.get_header_value("Authorization");
  if (h.rfind("Bearer ", 0) != 0) return std::nullopt;
  return auth_.session(h.substr(7));
}

void WebServer::routes() {
  auto asset = [](std::string_view body, const char* type) {
    return [body, type](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      res.set_content(body.data(), body.size(), type);
    };
  };
  http_->Get("/", asset(web::kIndexHtml, "text/html; charset=utf-8"));
  http_->Get("/app.js", asset(web::kAppJs, "text/javascript; charset=utf-8"));
  http_->Get("/style.css", asset(web::kStyleCss, "text/css; charset=utf-8"));
  http_->Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
  if (!http_->set_mount_point("/js", kDygraphsDir))
    spdlog::warn("dashboard: {} is missing (Debian's libjs-dygraphs): the page has no plots", kDygraphsDir);

  http_->Get("/api/fleet", [this](const httplib::Request&, httplib::Response& res) {
    reply(res, 200, {{"cells", fleet_.overview()}});
  });
  http_->Get(R"(/api/cells/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const auto d = fleet_.detail(req.matches[1], 0);
    if (!d) return refuse(res, 404, "no cell named '" + std::string(req.matches[1]) + "' has been heard on the domain");
    reply(res, 200, *d);
  });
  http_->Get("/api/health", [this](const httplib::Request&, httplib::Response& res) { reply(res, 200, health()); });
  http_->Get("/api/actions", [this](const httplib::Request&, httplib::Response& res) {
    json out = json::array();
    for (const auto& a : log_.recent(50))
      out.push_back({{"time", a.time_utc},
                     {"user", a.user},
                     {"cell", a.cell},
                     {"action", a.action},
                     {"value", a.value},
                     {"accepted", a.accepted},
                     {"reason", a.reason}});
    reply(res, 200, out);
  });
  http_->Post("/api/login", [this](const httplib::Request& req, httplib::Response& res) {
    const json body = json::parse(req.body, nullptr, false);
    if (body.is_discarded() || !body.is_object() || !body.contains("user") || !body.contains("password") ||
        !body["user"].is_string() || !body["password"].is_string())
      return refuse(res, 400, "a login is a JSON object {\"user\": text, \"password\": text}");
    const LoginResult r = auth_.login(body["user"], body["password"], req.remote_addr);
    if (r.outcome == LoginOutcome::kThrottled) {
      res.set_header("Retry-After", std::to_string(static_cast<int>(std::ceil(r.retry_after_s))));
      return refuse(res, 429,
                    "too many wrong passwords: try again in " +
                        std::to_string(static_cast<int>(std::ceil(r.retry_after_s))) + " s");
    }
    if (r.outcome == LoginOutcome::kWrong) return refuse(res, 401, "wrong user or password");
    reply(res, 200, {{"token", r.token}, {"user", body["user"]}, {"role", to_string(r.role)}});
  });
  http_->Post("/api/logout", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string h = req.get_header_value("Authorization");
    if (h.rfind("Bearer ", 0) == 0) auth_.logout(h.substr(7));
    reply(res, 200, {{"role", "observer"}});
  });
  http_->Get("/api/whoami", [this](const httplib::Request& req, httplib::Response& res) {
    const auto s = session_of(req);
    reply(res, 200,
          s ? json{{"user", s->user}, {"role", to_string(s->role)}} : json{{"user", nullptr}, {"role", "observer"}});
  });
  http_->Post(R"(/api/cells/([^/]+)/action)",
              [this](const httplib::Request& req, httplib::Response& res) { action(req, res); });
  http_->Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) { events(req, res); });
}

void WebServer::action(const httplib::Request& req, httplib::Response& res) {
  const std::string cell = req.matches[1];
  const auto s = session_of(req);
  if (!s) {
    ++n_->unauthenticated;
    return refuse(res, 401, "log in as an operator to act on a cell");
  }
  const json body = json::parse(req.body, nullptr, false);
  const ActionKind* kind = nullptr;
  if (!body.is_discarded() && body.is_object() && body.contains("action") && body["action"].is_string())
    for (const auto& k : kActions)
      if (body["action"] == k.name) kind = &k;
  if (kind == nullptr)
    return refuse(res, 400, "an action is {\"action\": arm|disarm|reset|gain|set|spindle, \"value\": number}");
  double value = kind->name == std::string("arm") ? 1.0 : 0.0;
  if (kind->needs_value) {
    if (!body.contains("value") || !body["value"].is_number() || !std::isfinite(body["value"].get<double>()))
      return refuse(res, 400,
                    std::string(kind->name) + " needs a finite number \"value\" (" +
                        (kind->kind == dds::RequestKind::kSetGain         ? "N s/m"
                         : kind->kind == dds::RequestKind::kSetSpindleRpm ? "rpm"
                                                                          : "set index") +
                        ")");
    value = body["value"].get<double>();
  }
  ActionRecord rec{now_utc_iso8601(), s->user, to_string(s->role), req.remote_addr, cell, kind->name, value, false, {}};
  if (s->role != Role::kOperator) {
    ++n_->forbidden;
    rec.reason =
        "refused by the dashboard: " + s->user + " is an observer (observers see everything and change nothing)";
    log_.append(rec);
    return refuse(res, 403, rec.reason);
  }
  if (!fleet_.known(cell))
    return refuse(res, 404, "no cell named '" + cell.substr(0, 64) + "' has been heard on the domain");
  ++n_->actions;
  const RequestOutcome r = fleet_.request(cell, kind->kind, value, s->user, cfg_.reply_timeout_s);
  rec.accepted = r.accepted;
  rec.reason = r.reason;
  log_.append(rec);
  if (r.accepted) ++n_->actions_accepted;
  reply(res, r.answered ? 200 : 504,
        {{"cell", cell},
         {"action", kind->name},
         {"value", value},
         {"answered", r.answered},
         {"accepted", r.accepted},
         {"reason", r.reason},
         {"user", s->user}});
}

void WebServer::events(const httplib::Request& req, httplib::Response& res) {
  if (streams_.fetch_add(1) >= cfg_.max_event_streams) {
    --streams_;
    ++n_->streams_refused;
    return refuse(res, 503,
                  "too many open pages (dashboard.max_event_streams = " + std::to_string(cfg_.max_event_streams) + ")");
  }
  ++n_->streams_opened;
  struct Stream {
    std::string cell;
    std::uint64_t seq{0}, urgent{~0ULL}, version{0};
    Clock::time_point fleet_at{}, cell_at{}, slow_at{}, alive_at{Clock::now()};
  };
  auto st = std::make_shared<Stream>();
  st->cell = req.get_param_value("cell");
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Accel-Buffering", "no");
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, st](std::size_t, httplib::DataSink& sink) {
        if (stopping_) return sink.done(), true;
        const std::uint64_t urgent = fleet_.wait(st->urgent, std::chrono::milliseconds(100), false);
        const auto now = Clock::now();
        const bool is_urgent = urgent != st->urgent;
        const std::uint64_t version = fleet_.version();
        std::string out;
        if (is_urgent || (version != st->version && now - st->fleet_at >= std::chrono::milliseconds(200))) {
          out += "event: fleet\ndata: " +
                 dump({{"cells", fleet_.overview()},
                       {"sent_ms", std::chrono::duration_cast<std::chrono::milliseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count()}}) +
                 "\n\n";
          st->fleet_at = now;
        }
        if (!st->cell.empty() && (is_urgent || now - st->cell_at >= std::chrono::milliseconds(100))) {
          const bool slow = now - st->slow_at >= std::chrono::seconds(1);  // spectrum and lobes once a second
          if (auto d = fleet_.detail(st->cell, st->seq, slow)) {
            st->seq = (*d)["telemetry"]["last_seq"].get<std::uint64_t>();
            out += "event: cell\ndata: " + dump(*d) + "\n\n";
            if (slow) st->slow_at = now;
          }
          st->cell_at = now;
        }
        st->urgent = urgent;
        st->version = version;
        if (out.empty() && now - st->alive_at >= std::chrono::seconds(5)) out = ": alive\n\n";  // finds a closed page
        if (out.empty()) return true;
        st->alive_at = now;
        ++n_->events;
        return sink.write(out.data(), out.size());
      },
      [this](bool) { --streams_; });
}

ServerCounters WebServer::counters() const {
  return {n_->requests,         n_->client_errors,   n_->server_errors,   n_->too_large,
          n_->not_found,        n_->unauthenticated, n_->forbidden,       n_->actions,
          n_->actions_accepted, n_->streams_opened,  n_->streams_refused, n_->events};
}

json WebServer::health() const {
  const ServerCounters c = counters();
  const FleetCounters f = fleet_.counters();
  const AuthCounters a = auth_.counters();
  return {{"http",
           {{"requests", c.requests},
            {"client_errors", c.client_errors},
            {"server_errors", c.server_errors},
            {"too_large", c.too_large},
            {"not_found", c.not_found},
            {"unauthenticated", c.unauthenticated},
            {"forbidden", c.forbidden},
            {"actions", c.actions},
            {"actions_accepted", c.actions_accepted},
            {"streams_open", streams_.load()},
            {"streams_opened", c.streams_opened},
            {"streams_refused", c.streams_refused},
            {"events", c.events}}},
          {"dds",
           {{"client", fleet_.client_name()},
            {"samples", f.samples},
            {"bad_cell_names", f.bad_cell_names},
            {"foreign_replies", f.foreign_replies},
            {"requests", f.requests},
            {"replies", f.replies},
            {"reply_timeouts", f.reply_timeouts},
            {"cells_lost", f.cells_lost},
            {"cells_restarted", f.cells_restarted},
            {"cells_refused", f.cells_refused}}},
          {"auth",
           {{"logins", a.logins},
            {"wrong_passwords", a.wrong_passwords},
            {"throttled", a.throttled},
            {"bad_tokens", a.bad_tokens},
            {"logouts", a.logouts},
            {"operators_configured", auth_.anyone_may_act()}}},
          {"action_log", log_.path()}};
}

}  // namespace robodamp::dashboard
