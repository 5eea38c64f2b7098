// The dashboard's parts without a browser (docs/dashboard.md): passwords, sessions and throttling, the
// credentials file, its configuration's refusals, the fleet seen from two named cells on one DDS domain
// (requests reach only the cell they name), and the spectrum a cell publishes. The page itself is tested in
// headless Chromium by tests/browser/test_dashboard.py.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>

#include "config/config.hpp"
#include "config/dashboard_config.hpp"
#include "dashboard/auth.hpp"
#include "dashboard/fleet.hpp"
#include "dashboard/server.hpp"
#include "dashboard/tls.hpp"
#include "dds/bridge.hpp"
#include "dds/messages.hpp"
#include "dds/participant.hpp"
#include "rt/supervisor.hpp"
#include "runtime/spectrum_monitor.hpp"

namespace robodamp {
namespace {

using Clock = dashboard::Authenticator::Clock;

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "dashboard_" + std::to_string(getpid()) + "_" + name;
}

template <typename F>
bool eventually(F f, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (f()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return f();
}

TEST(DashboardAuth, PasswordsAreSaltedHashesThatVerifyOnlyTheRightPassword) {
  const std::string h1 = dashboard::hash_password("correct horse", 2000),
                    h2 = dashboard::hash_password("correct horse", 2000);
  EXPECT_NE(h1, h2) << "a fresh salt each time";
  EXPECT_EQ(h1.rfind("pbkdf2-sha256$2000$", 0), 0U);
  EXPECT_TRUE(dashboard::verify_password("correct horse", h1));
  EXPECT_FALSE(dashboard::verify_password("correct horsE", h1));
  EXPECT_FALSE(dashboard::verify_password("", h1));
  for (const char* bad : {"", "pbkdf2-sha256$", "md5$1$aa$bb", "pbkdf2-sha256$x$aa$bb", "pbkdf2-sha256$2000$zz$bb",
                          "pbkdf2-sha256$1$00$00"})
    EXPECT_FALSE(dashboard::verify_password("anything", bad)) << bad;
}

TEST(DashboardAuth, WrongPasswordsAreThrottledPerUserAndAddressAndSessionsExpire) {
  dashboard::Authenticator auth({{"alice", dashboard::Role::kOperator, dashboard::hash_password("alice-pass", 2000)},
                                 {"bob", dashboard::Role::kObserver, dashboard::hash_password("bob-pass", 2000)}},
                                60.0);
  const auto t0 = Clock::now();
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(auth.login("alice", "nope", "10.0.0.1", t0).outcome, dashboard::LoginOutcome::kWrong);
  EXPECT_EQ(auth.login("alice", "nope", "10.0.0.1", t0).outcome,
            dashboard::LoginOutcome::kWrong);  // the 4th: locked 1 s
  const auto locked = auth.login("alice", "alice-pass", "10.0.0.2", t0 + std::chrono::milliseconds(500));
  EXPECT_EQ(locked.outcome, dashboard::LoginOutcome::kThrottled) << "by user, from another address too";
  EXPECT_GT(locked.retry_after_s, 0.0);
  EXPECT_EQ(auth.login("bob", "bob-pass", "10.0.0.1", t0 + std::chrono::milliseconds(500)).outcome,
            dashboard::LoginOutcome::kThrottled)
      << "by address, for another user too";
  const auto ok = auth.login("alice", "alice-pass", "10.0.0.1", t0 + std::chrono::seconds(2));
  ASSERT_EQ(ok.outcome, dashboard::LoginOutcome::kOk);
  EXPECT_EQ(ok.role, dashboard::Role::kOperator);
  EXPECT_EQ(ok.token.size(), 64U);
  EXPECT_EQ(auth.login("mallory", "alice-pass", "10.0.0.3", t0).outcome, dashboard::LoginOutcome::kWrong);
  // The lock-out doubles per further failure: 1, 2, 4 s ...
  const auto t1 = t0 + std::chrono::seconds(10);
  for (int i = 0; i < 5; ++i) (void)auth.login("bob", "x", "10.0.0.9", t1 + std::chrono::seconds(100 * i));
  EXPECT_EQ(auth.login("bob", "bob-pass", "10.0.0.8", t1 + std::chrono::seconds(401)).outcome,
            dashboard::LoginOutcome::kThrottled);
  EXPECT_EQ(auth.login("bob", "bob-pass", "10.0.0.8", t1 + std::chrono::seconds(420)).outcome,
            dashboard::LoginOutcome::kOk);

  const auto s = auth.session(ok.token, t0 + std::chrono::seconds(30));
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->user, "alice");
  EXPECT_TRUE(auth.session(ok.token, t0 + std::chrono::seconds(80)).has_value()) << "used at 30 s: idle 50 s";
  EXPECT_FALSE(auth.session(ok.token, t0 + std::chrono::seconds(200)).has_value()) << "idle past session_idle_s";
  EXPECT_FALSE(auth.session("deadbeef").has_value());
  EXPECT_GE(auth.counters().throttled, 3U);
  EXPECT_GE(auth.counters().bad_tokens, 1U);
}

TEST(DashboardAuth, TheCredentialsFileIsWrittenPrivatelyAndReadBackOrRefusedByKey) {
  const std::string path = temp("users.yaml");
  std::remove(path.c_str());
  dashboard::save_user(path, {"alice", dashboard::Role::kOperator, dashboard::hash_password("alice-pass", 2000)});
  dashboard::save_user(path, {"bob", dashboard::Role::kObserver, dashboard::hash_password("bob-pass", 2000)});
  dashboard::save_user(path,
                       {"alice", dashboard::Role::kObserver, dashboard::hash_password("new-pass", 2000)});  // replaced
  struct stat st {};
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600U);
  const auto users = dashboard::load_users(path);
  ASSERT_EQ(users.size(), 2U);
  EXPECT_EQ(users[0].name, "alice");
  EXPECT_EQ(users[0].role, dashboard::Role::kObserver);
  EXPECT_TRUE(dashboard::verify_password("new-pass", users[0].hash));
  EXPECT_THROW(dashboard::save_user(path, {"bad name!", dashboard::Role::kObserver, "x"}), std::runtime_error);

  std::ofstream(path) << "users:\n  - {name: carol, role: admin, hash: 'pbkdf2-sha256$2000$00$00'}\n";
  try {
    (void)dashboard::load_users(path);
    FAIL() << "a role that is not one";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("users[0].role"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("allowed operator or observer"), std::string::npos) << e.what();
  }
}

TEST(DashboardConfig, EveryKeyIsCheckedWithItsUnitAndRange) {
  const auto c =
      config::parse_dashboard_config("dashboard:\n  port: 0\n  stale_after_s: 1.5\ndds:\n  domain_id: 9\n", "d.yaml");
  EXPECT_EQ(c.port, 0);
  EXPECT_EQ(c.listen_address, "127.0.0.1") << "loopback unless told";
  EXPECT_EQ(c.stale_after_s, 1.5);
  EXPECT_EQ(c.dds.domain_id, 9);
  try {
    (void)config::parse_dashboard_config(
        "dashboard:\n  port: 70000\n  stale_after_s: -1\n  colour: red\n"
        "  credentials: /nonexistent/users.yaml\n",
        "d.yaml");
    FAIL() << "refused";
  } catch (const config::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("dashboard.port"), std::string::npos) << w;
    EXPECT_NE(w.find("65535"), std::string::npos) << w;
    EXPECT_NE(w.find("dashboard.stale_after_s"), std::string::npos) << w;
    EXPECT_NE(w.find("colour"), std::string::npos) << w;
    EXPECT_NE(w.find("/nonexistent/users.yaml"), std::string::npos) << w;
  }
  // HTTPS: both files or neither, each one there.
  try {
    (void)config::parse_dashboard_config("dashboard:\n  tls_certificate: /nonexistent/cert.pem\n", "d.yaml");
    FAIL() << "refused";
  } catch (const config::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("dashboard.tls_private_key: not given: HTTPS needs both the certificate and its private key"),
              std::string::npos)
        << w;
    EXPECT_NE(w.find("dashboard.tls_certificate = '/nonexistent/cert.pem': no such file (robodamp dashboard-cert"),
              std::string::npos)
        << w;
  }
  try {
    (void)config::parse_config(std::string("cell:\n  name: 'no spaces allowed'\n"), "c.yaml");
    FAIL() << "refused";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cell.name"), std::string::npos) << e.what();
  }
}

// A DDS domain of this test's own on the loopback (salt: one per test, so tests of one process do not meet).
config::DdsConfig loopback_dds(int salt) {
  config::DdsConfig cfg;
  cfg.domain_id = static_cast<int>((getpid() * 7 + salt) % 200) + 20;
  cfg.transport = config::DdsTransport::kUdpLoopback;
  return cfg;
}

// A loop's bridge as a cell publishes it, fed with frames here.
struct NamedCell {
  std::atomic<int> handled{0};
  std::atomic<int> resets{0};
  dds::Bridge bridge;
  NamedCell(const std::string& name, const config::DdsConfig& cfg, std::optional<dds::AdviceSample> advice = {})
      : bridge(cfg, 5000.0, name + ".yaml",
               {name,
                "simulated plant",
                [] { return std::size_t{0}; },
                [] { return 4000.0; },
                [this](dds::RequestKind k, double) {
                  ++handled;
                  if (k == dds::RequestKind::kResetFault) ++resets;
                  return dds::Decision{true, "ok"};
                },
                {},
                advice ? std::function<std::optional<dds::AdviceSample>()>([advice]() mutable {
                  ++advice->seq;  // a new one each time: the bridge publishes an advice once
                  return advice;
                })
                       : std::function<std::optional<dds::AdviceSample>()>()}) {
    bridge.start();
  }
  void frames(std::uint64_t from, int n, rt::State state) {
    for (std::uint64_t k = from; k < from + static_cast<std::uint64_t>(n); ++k) {
      rt::TelemetryFrame f;
      f.tick = k;
      f.time_s = static_cast<double>(k) / 5000.0;
      f.accel_mps2 = std::sin(static_cast<double>(k) * 0.03);
      f.state = static_cast<std::uint8_t>(state);
      bridge.on_frame(f);
    }
  }
};

TEST(DashboardFleet, TwoNamedCellsOnOneDomainAreToldApartAndARequestReachesOnlyItsCell) {
  config::DdsConfig cfg = loopback_dds(13);
  cfg.parameter_writes = true;
  cfg.status_rate_hz = 20.0;
  NamedCell a("cell-a", cfg);
  auto b_owner = std::make_unique<NamedCell>("cell-b", cfg);
  NamedCell& b = *b_owner;
  dashboard::Fleet fleet(cfg, 1.0);
  ASSERT_TRUE(eventually(
      [&] {
        a.frames(0, 500, rt::State::kActive), b.frames(0, 500, rt::State::kActive);
        return fleet.overview().size() == 2;
      },
      60.0));
  const auto tiles = fleet.overview();
  EXPECT_EQ(tiles[0]["cell"], "cell-a");
  EXPECT_EQ(tiles[1]["cell"], "cell-b");
  EXPECT_EQ(tiles[0]["state"], "active");
  // A request named for cell-b: cell-b answers, cell-a ignores it (and counts it).
  dashboard::RequestOutcome r;
  ASSERT_TRUE(eventually(
      [&] { return (r = fleet.request("cell-b", dds::RequestKind::kResetFault, 0.0, "alice", 2.0)).answered; }, 60.0));
  EXPECT_TRUE(r.accepted);
  EXPECT_GE(b.resets.load(), 1);
  // cell-a sees the same request on its own reader thread, possibly after cell-b has answered: wait for it.
  EXPECT_TRUE(eventually([&] { return a.bridge.counters().other_cells >= 1U; }, 30.0))
      << a.bridge.counters().other_cells;
  EXPECT_EQ(a.handled.load(), 0);
  // A trip wakes a waiting page at once; a cell that vanishes goes quiet after stale_after_s.
  const std::uint64_t seen = fleet.wait(0, std::chrono::milliseconds(0), false);
  b.frames(100000, 1, rt::State::kFault);
  EXPECT_GT(fleet.wait(seen, std::chrono::seconds(30), false), seen);
  b_owner.reset();
  ASSERT_TRUE(eventually(
      [&] {
        a.frames(200000, 50, rt::State::kActive);
        for (const auto& t : fleet.overview())
          if (t["cell"] == "cell-b") return !t["live"].get<bool>();
        return false;
      },
      30.0));
  EXPECT_GE(fleet.counters().cells_lost, 1U);
  const auto d = fleet.detail("cell-a", 0);
  ASSERT_TRUE(d.has_value());
  EXPECT_GT((*d)["telemetry"]["time_s"].size(), 10U);
  EXPECT_FALSE(fleet.detail("cell-c", 0).has_value());
}

// Two live cells under one name are a clash the tile shows (2 publishers); once one stops it is one again after
// stale_after_s (1 s here). The fleet forgets a quiet writer only after 5 x stale_after_s, and the tile counted
// every writer it remembered: a restarted cell showed "2 publishers" for 5 s (the browser test's screenshot;
// this test fails so, tried). Within 3.5 s here: 2.5 s for the bridges' samples on a loaded machine.
TEST(DashboardFleet, TwoLiveCellsUnderOneNameAreAClashUntilOneStops) {
  config::DdsConfig cfg = loopback_dds(29);
  cfg.status_rate_hz = 20.0;
  dashboard::Fleet fleet(cfg, 1.0);
  const auto publishers = [&] {
    const auto tiles = fleet.overview();
    return tiles.size() == 1 ? tiles[0]["publishers"].get<std::size_t>() : std::size_t{0};
  };
  auto first = std::make_unique<NamedCell>("same", cfg);
  auto second = std::make_unique<NamedCell>("same", cfg);
  std::uint64_t k = 0;
  const auto beat = [&] {
    if (first) first->frames(k, 50, rt::State::kActive);
    if (second) second->frames(k, 50, rt::State::kActive);
    k += 50;
  };
  EXPECT_TRUE(eventually(
      [&] {
        beat();
        return publishers() == 2;
      },
      60.0))
      << publishers();
  second.reset();  // stopped: quiet from now on
  EXPECT_TRUE(eventually(
      [&] {
        beat();
        return publishers() == 1;
      },
      3.5))
      << publishers();
}

// A cell that restarts is a new run: what its last run published is dropped when the new run's first status
// comes, so that no screen shows, and no operator follows, the old run's advice (the browser test once followed
// a killed run's advice and sent the speed to a cell still starting). A second run under the same name while
// the first still publishes is a clash, not a restart: nothing is dropped.
TEST(DashboardFleet, ARestartedCellsLastRunIsDropped) {
  config::DdsConfig cfg = loopback_dds(41);
  cfg.status_rate_hz = 20.0;
  dashboard::Fleet fleet(cfg, 1.0);
  dds::AdviceSample advice;
  advice.seq = 3, advice.found = true, advice.advised_rpm = 666.7, advice.trigger = "depth";
  auto first = std::make_unique<NamedCell>("again", cfg, advice);
  const auto detail = [&] { return fleet.detail("again", 0).value_or(nlohmann::json::object()); };
  ASSERT_TRUE(eventually(
      [&] {
        first->frames(0, 50, rt::State::kActive);
        return detail().contains("advice") && !detail()["advice"].is_null();
      },
      60.0))
      << detail();
  EXPECT_EQ(detail()["advice"]["advised_rpm"].get<double>(), 666.7);
  EXPECT_EQ(detail()["restarts"].get<std::uint64_t>(), 0U);
  // The same name again while the first still runs: a clash (two publishers), the advice kept.
  auto clash = std::make_unique<NamedCell>("again", cfg);
  ASSERT_TRUE(eventually(
      [&] {
        first->frames(100, 50, rt::State::kActive), clash->frames(100, 50, rt::State::kActive);
        return detail()["publishers"].get<std::size_t>() == 2;
      },
      60.0));
  EXPECT_EQ(detail()["restarts"].get<std::uint64_t>(), 0U);
  EXPECT_FALSE(detail()["advice"].is_null());
  first.reset(), clash.reset();
  // Both stopped; stale_after_s (1 s) later a new run under the name: the old run's advice is gone.
  ASSERT_TRUE(eventually([&] { return !detail()["live"].get<bool>(); }, 30.0));
  auto second = std::make_unique<NamedCell>("again", cfg);
  ASSERT_TRUE(eventually(
      [&] {
        second->frames(0, 50, rt::State::kActive);
        return detail()["restarts"].get<std::uint64_t>() == 1U;
      },
      60.0));
  EXPECT_TRUE(detail()["advice"].is_null()) << detail()["advice"];
  EXPECT_GE(fleet.counters().cells_restarted, 1U);
}

// A pose-scheduled cell's machining sample, live lobes and advice carry the robot's pose over DDS to the
// dashboard's JSON (what the page's pose row and lobes note read).
TEST(DashboardFleet, ThePoseTheLimitsAreForReachesThePage) {
  config::DdsConfig cfg = loopback_dds(43);
  cfg.status_rate_hz = 20.0;
  dashboard::Fleet fleet(cfg, 1.0);
  const std::vector<double> now{-100.3, 99.2, 90.1}, grid{-100.0, 100.0, 90.0};
  dds::MachiningSample m;
  m.spindle_rpm = 700.0, m.limits_ready = true, m.open_limit_mm = 0.098, m.damped_limit_mm = 0.098;
  m.pose_deg = now, m.limits_pose_deg = grid;
  dds::LobesSample l;
  l.rpm = {600.0, 700.0}, l.open_limit_mm = {0.1, 0.098}, l.damped_limit_mm = {0.1, 0.098}, l.pose_deg = grid;
  dds::AdviceSample a;
  a.seq = 1, a.found = true, a.advised_rpm = 650.0, a.pose_deg = grid;
  dds::Bridge bridge(cfg, 5000.0, "posed.yaml",
                     {"posed",
                      "simulated plant",
                      [] { return std::size_t{0}; },
                      [] { return 4000.0; },
                      [](dds::RequestKind, double) {
                        return dds::Decision{true, "ok"};
                      },
                      [m] { return m; },
                      [a]() mutable { return std::optional(a); },
                      {},
                      [l]() mutable { return std::optional(l); }});
  bridge.start();
  const auto detail = [&] { return fleet.detail("posed", 0, true).value_or(nlohmann::json::object()); };
  std::uint64_t tick = 0;
  ASSERT_TRUE(eventually(
      [&] {
        for (int i = 0; i < 50; ++i, ++tick) {
          rt::TelemetryFrame f;
          f.tick = tick, f.time_s = static_cast<double>(tick) / 5000.0,
          f.state = static_cast<std::uint8_t>(rt::State::kActive);
          bridge.on_frame(f);
        }
        const auto d = detail();
        return d.contains("machining") && d["machining"].contains("pose_deg") && d.contains("lobes") &&
               d["lobes"].is_object() && d.contains("advice") && d["advice"].is_object();
      },
      60.0))
      << detail();
  const auto d = detail();
  EXPECT_EQ(d["machining"]["pose_deg"].get<std::vector<double>>(), now);
  EXPECT_EQ(d["machining"]["limits_pose_deg"].get<std::vector<double>>(), grid);
  EXPECT_EQ(d["lobes"]["pose_deg"].get<std::vector<double>>(), grid);
  EXPECT_EQ(d["advice"]["pose_deg"].get<std::vector<double>>(), grid);
}

// More open pages than dashboard.max_event_streams are refused (503) and counted; a sample whose cell name is
// not a name is dropped and counted; the server stops with a page still open.
TEST(DashboardServer, ExtraPagesAndBadCellNamesAreRefusedAndCounted) {
  config::DashboardConfig cfg;
  cfg.port = 0;
  cfg.max_event_streams = 1;
  cfg.dds.domain_id = static_cast<int>((getpid() * 7 + 17) % 200) + 20;
  cfg.dds.transport = config::DdsTransport::kUdpLoopback;
  dashboard::Fleet fleet(cfg.dds, 2.0);
  dashboard::Authenticator auth({}, 60.0);
  dashboard::ActionLog log("");
  dashboard::WebServer server(cfg, fleet, auth, log);
  const int port = server.bind();
  std::thread serving([&] { server.serve(); });
  std::atomic<bool> first_event{false};
  std::thread page([&] {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(60, 0);
    (void)c.Get("/api/events", [&](const char*, std::size_t) { return first_event = true, true; });
  });
  EXPECT_TRUE(eventually([&] { return first_event.load(); }, 30.0));
  httplib::Client c("127.0.0.1", port);
  const auto second = c.Get("/api/events");
  ASSERT_TRUE(second);
  EXPECT_EQ(second->status, 503);
  EXPECT_NE(second->body.find("max_event_streams"), std::string::npos) << second->body;
  EXPECT_EQ(server.counters().streams_refused, 1U);

  dds::Participant writer(cfg.dds.domain_id, cfg.dds.transport, "bad names");
  auto* w = writer.writer(dds::TopicKind::kTelemetry);
  msg::Telemetry t;
  t.cell("bad name!");
  EXPECT_TRUE(eventually([&] { return w->write(&t), fleet.counters().bad_cell_names > 0; }, 60.0));
  EXPECT_TRUE(fleet.overview().empty());
  server.stop();
  serving.join();
  page.join();
}

// HTTPS (docs/dashboard.md, "HTTPS"): a pair from dashboard-cert serves the page to a client that verifies it
// against that certificate (by address and by name), with the secure headers on every response and no caching
// of the API's data; a plain client gets nothing; a key that is not the certificate's is refused by name;
// an existing file is not overwritten; plain HTTP is allowed on loopback only unless asked for.
TEST(DashboardServer, ServesHttpsWithItsCertificateAndSecureHeaders) {
  const std::string dir = temp("tls");
  std::filesystem::create_directories(dir);
  dashboard::write_self_signed(dir + "/cert.pem", dir + "/key.pem", {});
  dashboard::write_self_signed(dir + "/other.pem", dir + "/other.key", {});
  struct stat st {};
  ASSERT_EQ(::stat((dir + "/key.pem").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600U);
  try {
    dashboard::write_self_signed(dir + "/cert.pem", dir + "/new.key", {});
    ADD_FAILURE() << "an existing certificate was overwritten";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cert.pem: exists"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/new.key"));

  config::DashboardConfig cfg;
  cfg.port = 0;
  cfg.dds.domain_id = static_cast<int>((getpid() * 11 + 5) % 200) + 20;
  cfg.dds.transport = config::DdsTransport::kUdpLoopback;
  cfg.tls_certificate = dir + "/cert.pem";
  cfg.tls_private_key = dir + "/other.key";
  dashboard::Fleet fleet(cfg.dds, 2.0);
  dashboard::Authenticator auth({}, 60.0);
  dashboard::ActionLog log("");
  try {
    dashboard::WebServer mismatched(cfg, fleet, auth, log);
    ADD_FAILURE() << "a key that is not the certificate's was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dashboard.tls_private_key '" + dir + "/other.key'"), std::string::npos)
        << e.what();
  }
  cfg.tls_private_key = dir + "/key.pem";
  dashboard::WebServer server(cfg, fleet, auth, log);
  const int port = server.bind();
  std::jthread serving([&] { server.serve(); });
  for (const char* host : {"127.0.0.1", "localhost"}) {
    httplib::SSLClient c(host, port);
    c.set_ca_cert_path((dir + "/cert.pem").c_str());
    c.enable_server_certificate_verification(true);
    c.set_connection_timeout(30, 0);
    c.set_read_timeout(30, 0);
    for (const char* path : {"/", "/api/health", "/no-such-page"}) {
      const auto r = c.Get(path);
      ASSERT_TRUE(r) << host << path << ": " << httplib::to_string(r.error()) << " (verify "
                     << c.get_openssl_verify_result() << ")";
      EXPECT_EQ(r->status, std::string(path) == "/no-such-page" ? 404 : 200) << path;
      EXPECT_NE(r->get_header_value("Content-Security-Policy").find("frame-ancestors 'none'"), std::string::npos)
          << path;
      EXPECT_EQ(r->get_header_value("X-Content-Type-Options"), "nosniff") << path;
      EXPECT_EQ(r->get_header_value("X-Frame-Options"), "DENY") << path;
      EXPECT_EQ(r->get_header_value("Referrer-Policy"), "no-referrer") << path;
      if (std::string(path) != "/") {
        EXPECT_EQ(r->get_header_value("Cache-Control"), "no-store") << path;
      }
    }
  }
  // Verified against another certificate: refused.
  httplib::SSLClient wrong("127.0.0.1", port);
  wrong.set_ca_cert_path((dir + "/other.pem").c_str());
  wrong.enable_server_certificate_verification(true);
  EXPECT_FALSE(wrong.Get("/api/health"));
  httplib::Client plain("127.0.0.1", port);
  plain.set_read_timeout(10, 0);
  EXPECT_FALSE(plain.Get("/api/health")) << "plain HTTP answered on the HTTPS port";
  server.stop();
  serving.join();

  config::DashboardConfig open;
  for (const char* loopback : {"127.0.0.1", "127.3.2.1", "::1", "localhost"}) {
    open.listen_address = loopback;
    EXPECT_EQ(dashboard::plain_http_refusal(open, false), "") << loopback;
  }
  open.listen_address = "0.0.0.0";
  EXPECT_NE(
      dashboard::plain_http_refusal(open, false).find("plain HTTP on 0.0.0.0 is refused: passwords and session tokens"),
      std::string::npos);
  EXPECT_EQ(dashboard::plain_http_refusal(open, true), "") << "--insecure-http";
  open.tls_certificate = dir + "/cert.pem", open.tls_private_key = dir + "/key.pem";
  EXPECT_EQ(dashboard::plain_http_refusal(open, false), "");
  std::filesystem::remove_all(dir);
}

TEST(DashboardSpectrum, TheAccelerometersSpectrumPeaksAtItsSineWithTheModesAndToothPassing) {
  config::Config cfg =
      config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/horizontal_c2.yaml");
  cfg.spindle.teeth = 3;
  runtime::SpectrumMonitor m(cfg);
  EXPECT_EQ(m.display_rate_hz(), 1000.0);
  ASSERT_EQ(m.modes_hz().size(), 3U);
  EXPECT_FALSE(m.next().has_value()) << "nothing before the record is full";
  const double rate = cfg.loop.rate_hz;
  for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(9.0 * rate); ++k) {
    rt::TelemetryFrame f;
    f.tick = k;
    f.time_s = static_cast<double>(k) / rate;
    f.accel_mps2 = 0.2 * std::sin(2.0 * std::numbers::pi * 23.4 * f.time_s);
    if (k == 10) f.command_kind = static_cast<std::uint8_t>(rt::CommandKind::kSetSpindle), f.command_value = 700.0;
    m.on_frame(f);
  }
  const auto s = m.next();
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->tooth_passing_hz, 35.0, 1e-9);
  std::size_t peak = 0;
  for (std::size_t k = 1; k < s->accel_asd.size(); ++k)
    if (s->accel_asd[k] > s->accel_asd[peak]) peak = k;
  EXPECT_NEAR(static_cast<double>(peak) * s->bin_hz, 23.4, s->bin_hz);
  // Parseval: the density integrates to the sine's mean square (0.02 (m/s^2)^2), within the Hann leakage.
  double ms = 0.0;
  for (const float v : s->accel_asd) ms += static_cast<double>(v) * v * s->bin_hz;
  EXPECT_NEAR(ms, 0.02, 0.002);
  EXPECT_FALSE(m.next().has_value()) << "at most once per period_s of loop time";
}

}  // namespace
}  // namespace robodamp
