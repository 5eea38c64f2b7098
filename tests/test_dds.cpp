// Fast DDS: the loop's bridge publishing telemetry and status, and answering parameter requests, with
// subscriber and client participants in this process on UDP loopback (a domain of their own per run).
#include <gtest/gtest.h>

#include <regex>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sys/wait.h>
#include <thread>

#include <nlohmann/json.hpp>
#include <vector>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "analysis/pose_schedule.hpp"
#include "cell_util.hpp"
#include "config/config.hpp"
#include "config/robot_model_config.hpp"
#include "config/speed_schedule_config.hpp"
#include "child_process.hpp"
#include "dashboard/fleet.hpp"
#include "dds/bridge.hpp"
#include "dds/parameter_client.hpp"
#include "dds/participant.hpp"
#include "dds/messages.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using namespace eprosima::fastdds::dds;
using test::eventually;

int test_domain(int offset) { return static_cast<int>((getpid() * 7 + offset) % 200) + 20; }

template <typename T>
class Collect : public DataReaderListener {
 public:
  void on_data_available(DataReader* r) override {
    T v;
    SampleInfo info;
    while (r->take_next_sample(&v, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) {
        std::lock_guard<std::mutex> lock(m);
        got.push_back(v);
      }
  }
  std::size_t size() {
    std::lock_guard<std::mutex> lock(m);
    return got.size();
  }
  T last() {
    std::lock_guard<std::mutex> lock(m);
    return got.back();
  }
  std::vector<T> all() {
    std::lock_guard<std::mutex> lock(m);
    return got;
  }
  std::mutex m;
  std::vector<T> got;
};

// A client: the request writer, the reply and status readers, matched with the loop before use.
struct Client {
  Collect<msg::ParameterReply> replies;
  Collect<msg::Status> status;
  Collect<msg::Telemetry> telemetry;
  dds::Participant p;
  DataWriter* writer;
  DataReader* reply_reader;
  explicit Client(int domain, const std::optional<config::DdsSecurityConfig>& security = std::nullopt)
      : p(domain, config::DdsTransport::kUdpLoopback, "test client", security),
        writer(p.writer(dds::TopicKind::kRequest)),
        reply_reader(p.reader(dds::TopicKind::kReply, &replies)) {
    p.reader(dds::TopicKind::kStatus, &status);
    p.reader(dds::TopicKind::kTelemetry, &telemetry);
  }
  bool matched() {
    PublicationMatchedStatus pm;
    SubscriptionMatchedStatus sm;
    writer->get_publication_matched_status(pm);
    reply_reader->get_subscription_matched_status(sm);
    return pm.current_count > 0 && sm.current_count > 0;
  }
  msg::ParameterReply ask(std::uint32_t id, msg::RequestKind kind, double value) {
    (void)send(id, kind, value, 60.0);
    EXPECT_TRUE(reply(id)) << "request " << id << " answered within 60 s";
    return reply(id).value_or(msg::ParameterReply{});
  }
  // Asked again under a new id while unanswered: the client's side of a secured match may come before the
  // loop's, and a request written then is not delivered. Returns the ids asked; each reaches the loop at most once.
  std::vector<std::uint32_t> ask_until_answered(std::uint32_t first_id, msg::RequestKind kind, double value) {
    std::vector<std::uint32_t> asked;
    for (std::uint32_t id = first_id; asked.size() < 30; ++id) {
      asked.push_back(id);
      if (send(id, kind, value, 2.0)) return asked;
    }
    ADD_FAILURE() << "no request answered in 30 asks";
    return asked;
  }
  std::optional<msg::ParameterReply> reply(std::uint32_t id) {
    for (const auto& rep : replies.all())
      if (rep.request_id() == id) return rep;
    return std::nullopt;
  }

 private:
  bool send(std::uint32_t id, msg::RequestKind kind, double value, double wait_s) {
    msg::ParameterRequest r;
    r.client("test");
    r.cell(config::cell_name({}));
    r.request_id(id);
    r.kind(kind);
    r.value(value);
    writer->write(&r);
    return eventually([&] { return reply(id).has_value(); }, wait_s);
  }
};

TEST(Dds, TelemetryAndStatusReachASubscriberAndRequestsAreRefusedWhileWritesAreOff) {
  config::DdsConfig cfg;
  cfg.domain_id = test_domain(1);
  cfg.transport = config::DdsTransport::kUdpLoopback;
  cfg.telemetry_rate_hz = 100.0;
  cfg.status_rate_hz = 20.0;
  int handled = 0;
  dds::Bridge bridge(cfg, 5000.0, "test.yaml",
                     {config::cell_name({}),
                      "simulated plant",
                      [] { return std::size_t{0}; },
                      [] { return 4324.0; },
                      [&](dds::RequestKind, double) {
                        ++handled;
                        return dds::Decision{true, ""};
                      },
                      {}});
  bridge.start();
  Client client(cfg.domain_id);
  ASSERT_TRUE(eventually([&] { return client.matched(); }, 60.0));
  // One second of loop frames: a 2 m/s^2 square wave's RMS, 3 ticks in 10 saturated, state active but for
  // a stale-sensor trip from 0.4 to 0.6 s, the command derated from 0.8 s on.
  for (std::uint64_t k = 0; k < 5000; ++k) {
    rt::TelemetryFrame f;
    f.tick = k;
    f.time_s = static_cast<double>(k) / 5000.0;
    f.accel_mps2 = (k % 2) ? 2.0 : -2.0;
    f.command_v = 0.5;
    f.gain_ns_per_m = 2000.0;
    const bool tripped = k >= 2000 && k < 3000;
    f.state = static_cast<std::uint8_t>(tripped ? rt::State::kFault : rt::State::kActive);
    f.trip = static_cast<std::uint8_t>(tripped ? rt::Trip::kSensorStale : rt::Trip::kNone);
    f.flags = static_cast<std::uint16_t>(rt::kFlagFresh | ((k % 10 < 3) ? rt::kFlagSaturated : 0) |
                                         (k >= 4000 ? rt::kFlagDerated : 0));
    f.wake_latency_us = 12.0F;
    f.compute_us = 3.0F;
    bridge.on_frame(f);
    if (k % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Best effort: 100 windows sent; on a loaded machine the subscriber's socket may drop some, and this
  // test is about what a sample says, not about UDP under load.
  EXPECT_EQ(bridge.counters().telemetry, 100U);
  ASSERT_TRUE(eventually([&] { return client.telemetry.size() >= 1; }, 60.0));
  EXPECT_LE(client.telemetry.size(), 100U);
  const auto t = client.telemetry.last();
  EXPECT_NEAR(t.accel_rms_mps2(), 2.0, 1e-12);
  EXPECT_NEAR(t.saturated_fraction(), 0.3, 1e-6);
  EXPECT_DOUBLE_EQ(t.gain_ns_per_m(), 2000.0);
  ASSERT_TRUE(eventually([&] { return client.status.size() > 0 && client.status.last().tick() == 4999; }, 60.0));
  const auto s = client.status.last();
  EXPECT_EQ(std::string(s.state()), "active");
  EXPECT_EQ(std::string(s.trip()), "none");
  EXPECT_EQ(std::string(s.backend()), "simulated plant");
  EXPECT_FALSE(s.parameter_writes());
  EXPECT_DOUBLE_EQ(s.max_gain_ns_per_m(), 4324.0);
  EXPECT_NEAR(s.wake_p99_us(), 12.0, 1.0);
  // The availability the status carries: 0.2 s of the 1 s out, one trip at 0.4 s, back at full gain.
  EXPECT_NEAR(s.availability_pct(), 80.0, 0.1);
  EXPECT_EQ(s.trips(), 1U);
  EXPECT_EQ(s.back_at_full_gain(), 1U);
  EXPECT_NEAR(s.last_trip_s(), 0.4, 1e-9);
  EXPECT_TRUE(s.derated());
  EXPECT_NEAR(s.derated_pct(), 20.0, 0.1);  // 0.2 s of the 1 s asked

  const auto reply = client.ask(1, msg::SET_GAIN, 2500.0);
  EXPECT_FALSE(reply.accepted());
  EXPECT_NE(std::string(reply.reason()).find("dds.parameter_writes is false in test.yaml"), std::string::npos)
      << reply.reason();
  EXPECT_EQ(handled, 0);
  bridge.stop();
  EXPECT_EQ(bridge.counters().refused, 1U);
}

// The loop runs in this process (a cell activated for long enough, ended by deactivate() or, on a
// failed assertion, by the cell's destructor: no thread is left behind). Arming is the arming policy's,
// so the test waits for the state, not for a fixed tick.
TEST(Dds, ParameterRequestsAreValidatedLikeTheConfigurationAndApplied) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  // Sets an operator selects: a cell without the preset's speed schedule (a scheduled cell refuses set and,
  // inside a band, gain requests: test_speed_schedule).
  cfg.controller.speed_schedule.reset();
  config::DdsConfig d;
  d.domain_id = test_domain(2);
  d.transport = config::DdsTransport::kUdpLoopback;
  d.parameter_writes = true;
  cfg.dds = d;
  cfg.loop.clock = config::ClockKind::kWall;
  cfg.controller.harmonic_notch = config::HarmonicNotchConfig{};
  runtime::CellOptions o;
  o.realtime_setup = false;
  runtime::Cell cell(cfg, o);
  test::configure(cell);
  cell.add_parameter_set(config::load_config_file(test::preset("horizontal_c1")));
  ASSERT_TRUE(cell.activate(600.0).ok());
  Client client(d.domain_id);
  ASSERT_TRUE(eventually([&] { return client.matched(); }, 60.0));
  ASSERT_TRUE(eventually(
      [&] { return client.status.size() > 0 && std::string(client.status.last().state()) == "active"; }, 60.0))
      << "arming outcome " << runtime::to_string(cell.arming().outcome()) << ", last refusal "
      << rt::to_string(cell.arming().last_refusal());
  const double limit = client.status.last().max_gain_ns_per_m();
  EXPECT_NEAR(limit, cfg.supervision.max_gain_fraction * cell.supervisor().parameter_sets()[0].max_stable_gain_ns_per_m,
              1e-6);

  auto r = client.ask(1, msg::SET_GAIN, 90000.0);
  EXPECT_FALSE(r.accepted());
  EXPECT_NE(std::string(r.reason()).find("controller.gain_ns_per_m = 90000 N s/m is out of range"), std::string::npos)
      << r.reason();
  r = client.ask(2, msg::SET_GAIN, -1.0);
  EXPECT_FALSE(r.accepted());
  r = client.ask(3, msg::SELECT_PARAMETER_SET, 7.0);
  EXPECT_FALSE(r.accepted());
  EXPECT_NE(std::string(r.reason()).find("parameter_set = 7 is not a configured set"), std::string::npos) << r.reason();
  r = client.ask(4, msg::ENABLE, 2.0);
  EXPECT_FALSE(r.accepted());
  r = client.ask(5, msg::SET_GAIN, 2500.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually(
      [&] { return client.telemetry.size() > 0 && client.telemetry.last().gain_ns_per_m() > 2499.0; }, 60.0));
  r = client.ask(6, msg::SELECT_PARAMETER_SET, 1.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually([&] { return client.status.last().parameter_set() == 1; }, 60.0));
  r = client.ask(7, msg::SET_SPINDLE_RPM, 40000.0);
  EXPECT_FALSE(r.accepted());
  EXPECT_NE(std::string(r.reason())
                .find("spindle_rpm = 40000 rpm is out of range: allowed 0 <= value <= spindle.rpm_max = 30000 rpm"),
            std::string::npos)
      << r.reason();
  r = client.ask(8, msg::SET_SPINDLE_RPM, 12000.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  EXPECT_NE(std::string(r.reason()).find("12000 rpm x 3 teeth = 600 Hz"), std::string::npos) << r.reason();
  r = client.ask(9, msg::ENABLE, 0.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually([&] { return std::string(client.status.last().state()) == "disabled"; }, 60.0));
  ASSERT_TRUE(cell.deactivate().ok());
  EXPECT_EQ(cell.supervisor().controller().spindle_rpm(), 12000.0);  // the loop thread has ended: no race
  const runtime::RunSummary& summary = cell.summary();
  ASSERT_TRUE(summary.dds.has_value());
  EXPECT_EQ(summary.dds->requests, 9U);
  EXPECT_EQ(summary.dds->refused, 5U);
  EXPECT_EQ(summary.supervisor.params_selected, 1U);
  EXPECT_EQ(summary.trip, "none");
  EXPECT_EQ(summary.arming.outcome, runtime::ArmingOutcome::kArmed) << "the operator's disarm came after arming";
}

// The command-line tools against a `robodamp run` process: the live view and a refused request. The
// run lasts until the test ends it with SIGINT (exit 0 through the safe state), so nothing depends on
// how long arming or discovery take on a loaded machine.
TEST(Dds, MonitorShowsARunningLoopAndRequestSaysWhyItIsRefused) {
  const int domain = test_domain(3);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_cli_" + std::to_string(getpid());
  std::system(("mkdir -p " + dir).c_str());
  std::string text = test::read_file(test::preset("horizontal_c2"));
  text += "\ndds:\n  domain_id: " + std::to_string(domain) + "\n  transport: udp_loopback\n  telemetry_rate_hz: 20\n";
  // This test is about the command-line tools, not the overrun trip: on a loaded VM a wall-clock loop can
  // overrun 10 ticks running (the shipped limit), so here it may overrun for a whole second.
  text += "supervision:\n  overrun_cycles: 5000\n";
  std::ofstream(dir + "/dds.yaml") << text;
  test::Child run({"run", "--config", dir + "/dds.yaml", "--duration", "600"}, dir + "/run.log");
  std::string view;
  // The monitor shows what it sees: ask again until it has seen the loop active (or a minute passed).
  const bool seen = eventually(
      [&] {
        test::Child monitor({"monitor", "--config", dir + "/dds.yaml", "--duration", "3"}, dir + "/monitor.log");
        (void)monitor.wait_for(60.0);
        view = test::read_file(dir + "/monitor.log");
        return view.find("state      active") != std::string::npos;
      },
      60.0);
  EXPECT_TRUE(seen) << view << "\nrun log:\n" << test::read_file(dir + "/run.log");
  EXPECT_NE(view.find("m/s^2 RMS"), std::string::npos) << view;
  EXPECT_NE(view.find("wake-up p50"), std::string::npos) << view;
  EXPECT_NE(view.find("parameter writes off"), std::string::npos) << view;
  test::Child request({"request", "--config", dir + "/dds.yaml", "--gain", "2500", "--timeout", "60"},
                      dir + "/request.log");
  EXPECT_EQ(request.wait_for(120.0), std::optional<int>(3)) << test::read_file(dir + "/request.log");
  EXPECT_NE(test::read_file(dir + "/request.log").find("refused: parameter writes are off"), std::string::npos);
  // A monitor watching when the loop ends says so instead of freezing (issue 52).
  test::Child watching({"monitor", "--config", dir + "/dds.yaml", "--duration", "300"}, dir + "/watching.log");
  EXPECT_TRUE(test::file_says(dir + "/watching.log", "state      active", 60.0))
      << test::read_file(dir + "/watching.log");
  run.kill(SIGINT);
  EXPECT_EQ(run.wait_for(60.0), std::optional<int>(0)) << test::read_file(dir + "/run.log");
  EXPECT_TRUE(test::file_says(dir + "/watching.log", "NO CONTACT: nothing from", 60.0))
      << test::read_file(dir + "/watching.log");
  EXPECT_NE(test::read_file(dir + "/watching.log").find("the loop stopped or the link is down"), std::string::npos);
  watching.kill(SIGINT);
  EXPECT_TRUE(watching.wait_for(60.0).has_value());
  const std::string log = test::read_file(dir + "/run.log");
  EXPECT_NE(log.find("tripped: signal"), std::string::npos) << log;
  EXPECT_NE(log.find("arming: armed"), std::string::npos) << log;
  // The loop's changes are logged as they happen (the drain thread), not only in the summary at the end.
  EXPECT_NE(log.find("loop: active at"), std::string::npos) << log;
  EXPECT_NE(log.find("loop: tripped signal at"), std::string::npos) << log;
  EXPECT_LT(log.find("loop: tripped signal at"), log.find("tripped: signal")) << "before the summary";
  std::system(("rm -rf " + dir).c_str());
}

// A request with no loop to answer it: the library's exchange says no loop matched (it never sent), and
// `robodamp request` says so with status 1 after its --timeout. Domain 229 is outside test_domain's 20..219
// and the dashboard tests' domains, so no other test's loop can answer.
TEST(Dds, ARequestWithNoLoopOnItsDomainSaysSoAfterItsWait) {
  constexpr int kDomain = 229;
  msg::ParameterRequest req;
  req.client("test-no-loop");
  req.cell(config::cell_name({}));
  req.request_id(1);
  req.kind(msg::SET_GAIN);
  req.value(2500.0);
  const auto x = dds::request_parameter(kDomain, config::DdsTransport::kUdpLoopback, std::nullopt, req, 1.0);
  EXPECT_EQ(x.outcome, dds::ParameterExchange::Outcome::kNoLoop);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_no_loop_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  test::Child request({"request", "--domain", std::to_string(kDomain), "--transport", "udp_loopback", "--gain", "2500",
                       "--timeout", "1"},
                      dir + "/request.log");
  EXPECT_EQ(request.wait_for(60.0), std::optional<int>(1)) << test::read_file(dir + "/request.log");
  EXPECT_NE(test::read_file(dir + "/request.log").find("robodamp request: no loop on domain 229 within 1 s"),
            std::string::npos)
      << test::read_file(dir + "/request.log");
  std::filesystem::remove_all(dir);
}

// Live stability on DDS: `robodamp run` with a milling job (spindle.job), the spindle speed from a DDS
// request, and `robodamp monitor` showing the speed, the job's depth, the open and damped limits at that
// speed and the chatter indicator. Ends with SIGINT; every wait has a deadline and none is about speed.
TEST(Dds, MonitorShowsTheSpindleSpeedDepthLimitsAndChatterIndicator) {
  const int domain = test_domain(7);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_machining_" + std::to_string(getpid());
  std::system(("mkdir -p " + dir).c_str());
  std::string text = test::read_file(test::preset("horizontal_c2"));
  text += "\ndds:\n  domain_id: " + std::to_string(domain) +
          "\n  transport: udp_loopback\n  telemetry_rate_hz: 20\n  parameter_writes: true\n";
  text += "supervision:\n  overrun_cycles: 5000\n";
  text +=
      "spindle:\n  teeth: 3\n  job: " + std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml\n";
  // A name of its own: the monitor follows the configuration's cell, and another test's cell on a colliding
  // domain (test_domain is one of 200) is named after the host too (the hogged suite once showed that one).
  text += "cell:\n  name: dds-monitor-" + std::to_string(getpid()) + "\n";
  std::ofstream(dir + "/dds.yaml") << text;
  test::Child run({"run", "--config", dir + "/dds.yaml", "--duration", "600"}, dir + "/run.log");
  // The speed, asked until the loop is there to take it.
  const bool accepted = eventually(
      [&] {
        test::Child request({"request", "--config", dir + "/dds.yaml", "--spindle-rpm", "700", "--timeout", "20"},
                            dir + "/request.log");
        return request.wait_for(60.0) == std::optional<int>(0);
      },
      120.0);
  EXPECT_TRUE(accepted) << test::read_file(dir + "/request.log") << "\nrun log:\n" << test::read_file(dir + "/run.log");
  std::string view;
  const bool seen = eventually(
      [&] {
        test::Child monitor({"monitor", "--config", dir + "/dds.yaml", "--duration", "3"}, dir + "/monitor.log");
        (void)monitor.wait_for(60.0);
        view = test::read_file(dir + "/monitor.log");
        // The preset's speed schedule hands over to its 700 rpm band (C1 at K 3040) first: the view after it, with
        // the indicator's verdict (after a speed change it collects revolutions for a window first: a loaded run's
        // three seconds of monitor once fell inside that).
        // A status too (the parameter set comes with it; a loaded run's monitor once saw telemetry alone).
        return view.find("state      active") != std::string::npos && view.find("once-per-rev") != std::string::npos &&
               view.find("no status yet") == std::string::npos && view.find("damper active") != std::string::npos &&
               view.find("K = 3040 N s/m") != std::string::npos &&
               (view.rfind("collecting revolutions") == std::string::npos ||
                view.rfind("collecting revolutions") < view.rfind("once-per-rev"));
      },
      120.0);
  EXPECT_TRUE(seen) << view << "\nrun log:\n" << test::read_file(dir + "/run.log");
  EXPECT_NE(view.find("spindle    700 rpm (tooth passing 35.0 Hz), depth 0.500 mm"), std::string::npos) << view;
  // The schedule's promise at 700 rpm (config/presets/horizontal_c2.yaml's header: 2.350 mm; C2 at its fixed
  // K 2000 gave 0.782 mm there, below the open loop's 1.111 mm). The cell's live cache keys K to 10 N s/m and
  // the speed to its own step: within 0.2 %.
  std::smatch m;
  const std::string last = view.substr(view.rfind("stability  open"));
  ASSERT_TRUE(std::regex_search(
      last, m,
      std::regex(
          R"(open 1\.111 mm \(SDM\), damped ([0-9.]+) mm \(sampled-loop SDM\); now ([0-9.]+) mm \(damper active\)  depth within)")))
      << view;
  EXPECT_NEAR(std::stod(m[1]), 2.350, 0.005) << view;
  EXPECT_EQ(m[1], m[2]) << view;
  EXPECT_NE(view.find("parameter set 1"), std::string::npos) << view;
  EXPECT_NE(view.find("no chatter"), std::string::npos) << view;
  run.kill(SIGINT);
  EXPECT_EQ(run.wait_for(60.0), std::optional<int>(0)) << test::read_file(dir + "/run.log");
  const std::string log = test::read_file(dir + "/run.log");
  ASSERT_TRUE(std::regex_search(
      log, m,
      std::regex(
          R"(machining at the end: 700 rpm, depth 0\.500 mm; limit open 1\.111 mm \(SDM\), damped ([0-9.]+) mm \(sampled-loop SDM\))")))
      << log;
  EXPECT_NEAR(std::stod(m[1]), 2.350, 0.005) << log;
  // The preset's own schedule: its band count and the band the job's 699.3 rpm falls in.
  const config::Config preset = config::load_config_file(test::preset("horizontal_c2"));
  ASSERT_TRUE(preset.controller.speed_schedule.has_value());
  const auto& bands = preset.controller.speed_schedule->bands;
  const std::optional<std::size_t> at = config::speed_band_of(bands, 699.3);
  ASSERT_TRUE(at.has_value());
  EXPECT_NE(log.find("speed schedule: " + std::to_string(bands.size()) + " bands; at the end band " +
                     std::to_string(*at) + ", set 1 at K 3040 N s/m; 1 hand-overs"),
            std::string::npos)
      << log;
}

// --- ROS 2 conventions ---

// The topics and types under ROS 2's names, so a ROS 2 node (rclcpp on Fast DDS) with ros2/robodamp
// matches them: `ros2 topic echo /robodamp/telemetry robodamp/msg/Telemetry`.
TEST(Dds, TopicsAndTypesUseRos2Names) {
  dds::Participant p(test_domain(5), config::DdsTransport::kUdpLoopback, "ros2 names", std::nullopt);
  const std::pair<dds::TopicKind, std::pair<const char*, const char*>> expected[] = {
      {dds::TopicKind::kTelemetry, {"rt/robodamp/telemetry", "robodamp::msg::dds_::Telemetry_"}},
      {dds::TopicKind::kStatus, {"rt/robodamp/status", "robodamp::msg::dds_::Status_"}},
      {dds::TopicKind::kRequest, {"rt/robodamp/parameter_request", "robodamp::msg::dds_::ParameterRequest_"}},
      {dds::TopicKind::kReply, {"rt/robodamp/parameter_reply", "robodamp::msg::dds_::ParameterReply_"}},
      {dds::TopicKind::kMachining, {"rt/robodamp/machining", "robodamp::msg::dds_::Machining_"}},
      {dds::TopicKind::kAdvice, {"rt/robodamp/advice", "robodamp::msg::dds_::Advice_"}}};
  for (const auto& [kind, names] : expected) {
    EXPECT_EQ(p.topic(kind)->get_name(), names.first);
    EXPECT_EQ(p.topic(kind)->get_type_name(), names.second);
  }
}

// (type, name) pairs of a struct in dds/robodamp.idl, in ROS 2's spelling.
std::vector<std::pair<std::string, std::string>> idl_fields(const std::string& idl, const std::string& name) {
  const std::size_t at = idl.find("struct " + name + "_ {");
  EXPECT_NE(at, std::string::npos) << name;
  const std::size_t end = idl.find("};", at);
  std::istringstream body(idl.substr(idl.find('{', at) + 1, end - idl.find('{', at) - 1));
  const std::vector<std::pair<std::string, std::string>> types = {
      {"unsigned long long", "uint64"},
      {"unsigned long", "uint32"},
      {"double", "float64"},
      {"float", "float32"},
      {"octet", "uint8"},
      {"boolean", "bool"},
      {"long", "int32"},
      {"std_msgs::msg::dds_::Header_", "std_msgs/Header"},
      {"builtin_interfaces::msg::dds_::Time_", "builtin_interfaces/Time"},
      {"builtin_interfaces::msg::dds_::Duration_", "builtin_interfaces/Duration"},
      {"trajectory_msgs::msg::dds_::JointTrajectoryPoint_", "trajectory_msgs/JointTrajectoryPoint"}};
  std::vector<std::pair<std::string, std::string>> out;
  for (std::string line; std::getline(body, line);) {
    line = line.substr(0, line.find("//"));
    const std::size_t semi = line.find(';');
    if (semi == std::string::npos) continue;
    line = line.substr(line.find_first_not_of(' '), semi - line.find_first_not_of(' '));
    const std::size_t space = line.rfind(' ');
    std::string type = line.substr(0, space), field = line.substr(space + 1);
    if (type.rfind("string<", 0) == 0) type = "string<=" + type.substr(7, type.size() - 8);
    std::string bound;                      // sequence<T, N>: ROS 2's T[<=N]
    if (type.rfind("sequence<", 0) == 0) {  // sequence<T>: ROS 2's T[]
      const std::size_t comma = type.find(',');
      bound = comma == std::string::npos ? "[]" : "[<=" + type.substr(comma + 2, type.size() - comma - 3) + "]";
      type = type.substr(9, (comma == std::string::npos ? type.size() - 1 : comma) - 9);
    }
    for (const auto& [idl_type, ros_type] : types)
      if (type == idl_type) type = ros_type;
    type += bound;
    out.emplace_back(type, field);
  }
  return out;
}

// (type, name) pairs of a ROS 2 .msg file (constants and comments left out).
std::vector<std::pair<std::string, std::string>> msg_fields(const std::string& path) {
  std::istringstream in(test::read_file(path));
  std::vector<std::pair<std::string, std::string>> out;
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, field;
    if (!(words >> type >> field) || field.find('=') != std::string::npos) continue;
    out.emplace_back(type, field);
  }
  return out;
}

TEST(Dds, Ros2MsgFilesMatchTheIdlFieldForField) {
  const std::string idl = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/dds/robodamp.idl");
  for (const char* name :
       {"Telemetry", "Status", "ParameterRequest", "ParameterReply", "Machining", "Advice", "Spectrum", "Lobes"}) {
    const auto from_idl = idl_fields(idl, name);
    const auto from_msg = msg_fields(test::source_path(std::string("ros2/robodamp/msg/") + name + ".msg"));
    EXPECT_GT(from_idl.size(), 3U) << name;
    EXPECT_EQ(from_msg, from_idl) << name;
  }
  // The request kinds: the same numbers in both.
  const std::string request =
      test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/ros2/robodamp/msg/ParameterRequest.msg");
  EXPECT_NE(request.find("uint8 SET_GAIN=" + std::to_string(msg::SET_GAIN)), std::string::npos);
  EXPECT_NE(request.find("uint8 SELECT_PARAMETER_SET=" + std::to_string(msg::SELECT_PARAMETER_SET)), std::string::npos);
  EXPECT_NE(request.find("uint8 ENABLE=" + std::to_string(msg::ENABLE)), std::string::npos);
  EXPECT_NE(request.find("uint8 SET_SPINDLE_RPM=" + std::to_string(msg::SET_SPINDLE_RPM)), std::string::npos);
  EXPECT_NE(request.find("uint8 RESET_FAULT=" + std::to_string(msg::RESET_FAULT)), std::string::npos);
}

// The joint states are ROS 2's sensor_msgs/msg/JointState as its definition has it (the message and the two it
// holds), under the type and topic names a ROS 2 driver's /joint_states has on DDS.
TEST(Dds, JointStateIsRos2sMessageFieldForField) {
  using Fields = std::vector<std::pair<std::string, std::string>>;
  const std::string idl = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/dds/robodamp.idl");
  // sensor_msgs/msg/JointState.msg, std_msgs/msg/Header.msg, builtin_interfaces/msg/Time.msg (ROS 2).
  EXPECT_EQ(idl_fields(idl, "JointState"), (Fields{{"std_msgs/Header", "header"},
                                                   {"string[]", "name"},
                                                   {"float64[]", "position"},
                                                   {"float64[]", "velocity"},
                                                   {"float64[]", "effort"}}));
  EXPECT_EQ(idl_fields(idl, "Header"), (Fields{{"builtin_interfaces/Time", "stamp"}, {"string", "frame_id"}}));
  EXPECT_EQ(idl_fields(idl, "Time"), (Fields{{"int32", "sec"}, {"uint32", "nanosec"}}));
  dds::Participant p(test_domain(6), config::DdsTransport::kUdpLoopback, "joint state names", std::nullopt);
  DataWriter* w = p.joint_state_writer("rt/joint_states");
  EXPECT_EQ(w->get_topic()->get_name(), "rt/joint_states");
  EXPECT_EQ(w->get_topic()->get_type_name(), "sensor_msgs::msg::dds_::JointState_");
}

// A ROS 2 robot driver's joint states select the pose schedule's set, as the Modbus joint registers do
// (docs/pose_dynamics.md, "The pose over DDS"): `robodamp run` on config/presets/pose_scheduled_c2.yaml with
// dds.joint_states naming its three joints; a driver of the test's own publishes at 50 Hz, in radians, its
// joints in another order and with a gripper the schedule does not know. Folded: the loop arms on the folded
// set; stretched: handed over; a message without the elbow: the pose unknown (the loop trips out of the
// map); silence: said. Every wait has a deadline.
TEST(Dds, JointStatesFromARos2DriverSelectThePoseSchedulesSet) {
  const int domain = test_domain(7);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_joints_" + std::to_string(getpid());
  std::system(("mkdir -p " + dir).c_str());
  std::string text = test::read_file(test::preset("pose_scheduled_c2"));
  test::replace_or_throw(text, "model: ../robots/", std::string("model: ") + ROBODAMP_SOURCE_DIR + "/config/robots/");
  text += "\ncell:\n  name: joints-" + std::to_string(getpid()) + "\ndds:\n  domain_id: " + std::to_string(domain) +
          "\n  transport: udp_loopback\n  joint_states:\n    names: [shoulder, elbow, wrist]\n    timeout_s: 0.5\n"
          "supervision:\n  overrun_cycles: 5000\n";
  std::ofstream(dir + "/cell.yaml") << text;
  test::Child run({"run", "--config", dir + "/cell.yaml", "--duration", "600", "--json", dir + "/run.json"},
                  dir + "/run.log");
  // The listeners first: they outlive the participant whose threads call them (ThreadSanitizer found them
  // destroyed while its reader thread still delivered).
  Collect<msg::Status> status;      // the cell's own word on the set that runs
  Collect<msg::Spectrum> spectrum;  // its mode marks: the robot's modes at the pose
  dds::Participant driver(domain, config::DdsTransport::kUdpLoopback, "test robot driver", std::nullopt);
  DataWriter* w = driver.joint_state_writer("rt/joint_states");
  driver.reader(dds::TopicKind::kStatus, &status);
  driver.reader(dds::TopicKind::kSpectrum, &spectrum);
  const std::string cell = "joints-" + std::to_string(getpid());
  const auto running_set = [&](std::uint32_t set) {
    return eventually(
        [&] {
          for (const auto& s : status.all())
            if (s.cell() == cell && s.state() == "active" && s.parameter_set() == set) return true;
          return false;
        },
        60.0);
  };
  std::mutex m;
  std::vector<std::string> names{"wrist", "gripper", "shoulder", "elbow"};
  std::vector<double> deg{90.0, 12.0, -100.0, 10.0};  // folded
  std::atomic<bool> publishing{true}, stop{false};
  std::thread publisher([&] {
    while (!stop) {
      if (publishing) {
        msg::JointState js;
        {
          std::lock_guard lock(m);
          js.name(names);
          std::vector<double> rad;
          for (double d : deg) rad.push_back(d * M_PI / 180.0);
          js.position(rad);
        }
        js.header().frame_id("base_link");
        w->write(&js);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  const auto log_has = [&](const std::string& s, double deadline_s) {
    return test::file_says(dir + "/run.log", s, deadline_s);
  };
  EXPECT_TRUE(log_has("dds joint states: pose [-100, 10, 90] deg in region 'folded'", 60.0))
      << test::read_file(dir + "/run.log");
  EXPECT_TRUE(log_has("loop: active at", 60.0)) << test::read_file(dir + "/run.log");
  EXPECT_TRUE(running_set(0)) << "the folded region's set";
  {
    std::lock_guard lock(m);
    deg = {90.0, 12.0, -100.0, 80.0};  // stretched
  }
  EXPECT_TRUE(log_has("pose [-100, 80, 90] deg in region 'stretched'", 60.0)) << test::read_file(dir + "/run.log");
  EXPECT_TRUE(running_set(1)) << "handed over to the stretched region's set\n" << test::read_file(dir + "/run.log");
  {
    const config::Config cfg = config::load_config_file(dir + "/cell.yaml");
    const auto model = config::load_robot_model(cfg.pose_schedule->model_resolved);
    std::vector<float> stretched;
    for (const auto& md :
         analysis::pose_modes(model, {-100.0, 80.0, 90.0}, cfg.pose_schedule->axis, cfg.pose_schedule->modes).modes)
      stretched.push_back(static_cast<float>(md.natural_freq_hz));
    EXPECT_TRUE(eventually(
        [&] {
          for (const auto& s : spectrum.all())
            if (s.cell() == cell && s.mode_hz() == stretched) return true;
          return false;
        },
        60.0))
        << "the spectrum's mode marks at the stretched pose, " << stretched.front() << " Hz first";
  }
  {
    std::lock_guard lock(m);
    names = {"wrist", "gripper", "shoulder"}, deg = {90.0, 12.0, -100.0};  // the elbow missing
  }
  EXPECT_TRUE(log_has("a message with no joint 'elbow' (dds.joint_states.names): the pose is unknown", 60.0))
      << test::read_file(dir + "/run.log");
  EXPECT_TRUE(log_has("loop: tripped pose_out_of_map", 60.0)) << test::read_file(dir + "/run.log");
  publishing = false;
  EXPECT_TRUE(log_has("dds joint states on rt/joint_states: none for 0.5 s: the pose is unknown", 60.0))
      << test::read_file(dir + "/run.log");
  stop = true;
  publisher.join();
  run.kill(SIGINT);
  EXPECT_TRUE(run.wait_for(60.0).has_value()) << test::read_file(dir + "/run.log");
  const auto summary = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  const auto& js = summary["joint_states"];
  // Each region's pose settles over dds.joint_states.settle_samples (3) messages, and one at least was refused:
  // 7 or more. (It was "more than 20", which counted on the test's steps taking 0.4 s or more: in a fresh
  // clone's run they took 0.3 s and 11 came.)
  EXPECT_GE(js["messages"].get<int>(), 2 * 3 + js["refused"].get<int>()) << js.dump();
  EXPECT_GT(js["refused"].get<int>(), 0) << js.dump();
  EXPECT_GE(js["changes"].get<int>(), 3) << js.dump();  // folded, stretched, unknown
  EXPECT_EQ(js["losses"].get<int>(), 1) << js.dump();
  std::istringstream lines(test::read_file(dir + "/run.log"));
  for (std::string line; std::getline(lines, line);)
    if (line.find("joint") != std::string::npos || line.find("loop:") != std::string::npos)
      std::printf("%s\n", line.c_str());
  std::system(("rm -rf " + dir).c_str());
}

// The robot program's trajectory (ROS 2's trajectory_msgs/msg/JointTrajectory) as its definition has it, under the
// type and topic names a ROS 2 program's /joint_trajectory has on DDS.
TEST(Dds, JointTrajectoryIsRos2sMessageFieldForField) {
  using Fields = std::vector<std::pair<std::string, std::string>>;
  const std::string idl = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/dds/robodamp.idl");
  // trajectory_msgs/msg/JointTrajectory.msg, JointTrajectoryPoint.msg, builtin_interfaces/msg/Duration.msg (ROS 2).
  EXPECT_EQ(idl_fields(idl, "JointTrajectory"), (Fields{{"std_msgs/Header", "header"},
                                                        {"string[]", "joint_names"},
                                                        {"trajectory_msgs/JointTrajectoryPoint[]", "points"}}));
  EXPECT_EQ(idl_fields(idl, "JointTrajectoryPoint"), (Fields{{"float64[]", "positions"},
                                                             {"float64[]", "velocities"},
                                                             {"float64[]", "accelerations"},
                                                             {"float64[]", "effort"},
                                                             {"builtin_interfaces/Duration", "time_from_start"}}));
  EXPECT_EQ(idl_fields(idl, "Duration"), (Fields{{"int32", "sec"}, {"uint32", "nanosec"}}));
  dds::Participant p(test_domain(8), config::DdsTransport::kUdpLoopback, "trajectory names", std::nullopt);
  DataWriter* w = p.trajectory_writer("rt/joint_trajectory");
  EXPECT_EQ(w->get_topic()->get_name(), "rt/joint_trajectory");
  EXPECT_EQ(w->get_topic()->get_type_name(), "trajectory_msgs::msg::dds_::JointTrajectory_");
}

// The advice along the path ahead across processes (docs/pose_dynamics.md, "Advice along the path ahead"):
// `robodamp run` on the pose-scheduled preset with the planar robot's wall cut 0.4 mm deep at 700 rpm (above
// its limit: the cell asks for advice), the pose from a driver of the test's own (folded) and the robot
// program's trajectory on to stretched. The cell's advice is checked at the pose and the poses ahead, says so
// on the Advice topic with the pose where the limit is lowest, and the run summary counts the trajectories.
TEST(Dds, TheAdviceIsCheckedAlongTheTrajectoryTheRobotProgramPublishes) {
  const int domain = test_domain(9);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_path_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  std::string job = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/planar_three_link_wall_x.yaml");
  test::replace_or_throw(job, "model: ../robots/", std::string("model: ") + ROBODAMP_SOURCE_DIR + "/config/robots/");
  test::replace_or_throw(job, "axial_mm: 0.1", "axial_mm: 0.4");
  // The advice searched over 550-850 rpm, not the job's 100-1500, with 4 grid speeds beside the pockets, not 48
  // (spindle.advice_grid_points): what is checked is where it looks (the pose and the path ahead), not what it
  // finds, and each candidate costs an accurate limit at every pose.
  test::replace_or_throw(job, "rpm_min: 100", "rpm_min: 550");
  test::replace_or_throw(job, "rpm_max: 1500", "rpm_max: 850");
  std::ofstream(dir + "/job.yaml") << job;
  std::string text = test::read_file(test::preset("pose_scheduled_c2"));
  test::replace_or_throw(text, "model: ../robots/", std::string("model: ") + ROBODAMP_SOURCE_DIR + "/config/robots/");
  const std::string cell = "path-" + std::to_string(getpid());
  text += "\ncell:\n  name: " + cell + "\nspindle:\n  teeth: 3\n  advice_grid_points: 4\n  job: " + dir +
          "/job.yaml\ndds:\n  domain_id: " + std::to_string(domain) +
          "\n  transport: udp_loopback\n  joint_states:\n    names: [shoulder, elbow, wrist]\n  path_ahead: {}\n"
          "supervision:\n  overrun_cycles: 5000\n";
  std::ofstream(dir + "/cell.yaml") << text;
  test::Child run(
      {"run", "--config", dir + "/cell.yaml", "--duration", "600", "--spindle-rpm", "700", "--json", dir + "/run.json"},
      dir + "/run.log");
  Collect<msg::Advice> advice;  // first: it outlives the participant whose thread calls it
  dds::Participant program(domain, config::DdsTransport::kUdpLoopback, "test robot program", std::nullopt);
  DataWriter* joints = program.joint_state_writer("rt/joint_states");
  DataWriter* trajectory = program.trajectory_writer("rt/joint_trajectory");
  program.reader(dds::TopicKind::kAdvice, &advice);
  const double r = M_PI / 180.0;
  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    for (int i = 0; !stop; ++i) {
      msg::JointState js;
      js.name({"shoulder", "elbow", "wrist"});
      js.position({-100 * r, 10 * r, 90 * r});  // folded
      joints->write(&js);
      if (i % 25 == 0) {  // the program's next poses, twice a second: on to stretched in 20 and 40 s
        msg::JointTrajectory t;
        t.joint_names({"wrist", "elbow", "shoulder"});
        for (const auto& [elbow, due_s] : {std::pair{10.0, 0}, {56.0, 20}, {100.0, 40}}) {
          msg::JointTrajectoryPoint p;
          p.positions({90 * r, elbow * r, -100 * r});
          p.time_from_start().sec(due_s);
          t.points().push_back(p);
        }
        trajectory->write(&t);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  std::optional<msg::Advice> along;
  const bool heard = eventually(
      [&] {
        for (const auto& a : advice.all())
          if (a.cell() == cell && a.poses_ahead() > 0) along = a;
        return along.has_value();
      },
      480.0 * test::pace());  // within ctest's 600 s (scripts/test.sh); a sanitizer build's 3600 s
  stop = true;
  publisher.join();
  run.kill(SIGINT);
  // The loop is safe at once; the process ends when the monitor's worker has finished the accurate limit it is
  // computing (under ThreadSanitizer one took more than 60 s, 2026-12-07).
  EXPECT_TRUE(run.wait_for(60.0 * test::pace()).has_value()) << test::read_file(dir + "/run.log");
  ASSERT_TRUE(heard) << "no advice checked along the path\n" << test::read_file(dir + "/run.log");
  EXPECT_EQ(along->pose_deg(), (std::vector<double>{-100.0, 10.0, 90.0}));
  EXPECT_EQ(along->poses_ahead(), 2U);  // the pose now, repeated first in the trajectory, is checked once
  EXPECT_EQ(along->limiting_pose_deg().size(), 3U);
  const auto summary = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  EXPECT_GT(summary["path_ahead"]["messages"].get<int>(), 0) << summary.dump();
  EXPECT_EQ(summary["path_ahead"]["refused"].get<int>(), 0) << summary.dump();
  // The run summary's advice (as `robodamp monitor` prints the topic's) says where it was checked.
  EXPECT_EQ(summary["advice"]["poses_ahead"].get<int>(), 2) << summary["advice"].dump();
  EXPECT_NE(test::read_file(dir + "/run.log")
                .find("at the robot's pose [-100, 10, 90] deg and 2 poses of the path ahead (the lowest limit at"),
            std::string::npos)
      << test::read_file(dir + "/run.log");
  std::cout << "advice #" << along->seq() << ": "
            << (along->found() ? "found " + std::to_string(along->advised_rpm()) + " rpm" : along->reason())
            << "; lowest limit at " << config::describe_pose(along->limiting_pose_deg()) << "\n";
  std::filesystem::remove_all(dir);
}

// --- DDS Security ------------------------------------------------------------------------------------------

// Certificates, keys, governance and permissions made by scripts/dds_security.sh with openssl, once.
const std::string& security_dir() {
  static const std::string dir = [] {
    const std::string d = ::testing::TempDir() + "robodamp_dds_security_" + std::to_string(getpid());
    const std::string cmd =
        "bash " + std::string(ROBODAMP_SOURCE_DIR) + "/scripts/dds_security.sh " + d + " > /dev/null";
    if (std::system(cmd.c_str()) != 0) return std::string();
    return d;
  }();
  return dir;
}

config::DdsSecurityConfig identity(const std::string& who) {
  const std::string d = security_dir() + "/";
  return {d + "ca.pem", d + who + ".pem",       d + who + ".key",
          d + "ca.pem", d + "governance.smime", d + who + "_permissions.smime"};
}

struct SecureLoop {
  config::DdsConfig cfg;
  std::atomic<int> handled{0};
  std::unique_ptr<dds::Bridge> bridge;
  explicit SecureLoop(int domain) {
    cfg.domain_id = domain;
    cfg.transport = config::DdsTransport::kUdpLoopback;
    cfg.telemetry_rate_hz = 100.0;
    cfg.parameter_writes = true;
    cfg.security = identity("loop");
    bridge = std::make_unique<dds::Bridge>(cfg, 5000.0, "secure.yaml",
                                           dds::BridgeSources{config::cell_name({}),
                                                              "simulated plant",
                                                              [] { return std::size_t{0}; },
                                                              [] { return 4324.0; },
                                                              [this](dds::RequestKind, double v) {
                                                                ++handled;
                                                                return dds::Decision{true, "K = " + std::to_string(v)};
                                                              },
                                                              {}});
    bridge->start();
  }
  ~SecureLoop() { bridge->stop(); }
  std::uint64_t tick{0};
  void publish_frames(int n) {  // ticks go on from call to call, as the loop's do
    for (int k = 0; k < n; ++k, ++tick) {
      rt::TelemetryFrame f;
      f.tick = tick;
      f.time_s = static_cast<double>(tick) / 5000.0;
      f.state = static_cast<std::uint8_t>(rt::State::kActive);
      bridge->on_frame(f);
      if (k % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
};

// op (an authorised operator in the loop's domain) matches and asks for K = 2500 N s/m (ids from first_id) until
// answered: accepted with its own value, and only its requests reached the loop, each at most once.
void expect_operator_answered(SecureLoop& loop, Client& op, std::uint32_t first_id) {
  ASSERT_TRUE(eventually([&] { return op.matched(); }, 60.0)) << "authentication and matching";
  const auto asked = op.ask_until_answered(first_id, msg::SET_GAIN, 2500.0);
  const auto r = op.reply(asked.back());
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->accepted()) << r->reason();
  EXPECT_NE(std::string(r->reason()).find("K = 2500"), std::string::npos) << r->reason() << ": the operator's value";
  EXPECT_GE(loop.handled.load(), 1);
  EXPECT_LE(loop.handled.load(), static_cast<int>(asked.size())) << "only the operator's requests, each at most once";
}

TEST(DdsSecurity, AnAuthorisedOperatorsRequestReachesTheLoop) {
  ASSERT_FALSE(security_dir().empty()) << "scripts/dds_security.sh failed (openssl)";
  SecureLoop loop(test_domain(4));
  Client op(loop.cfg.domain_id, identity("operator"));
  ASSERT_NO_FATAL_FAILURE(expect_operator_answered(loop, op, 1));
  EXPECT_TRUE(eventually([&] { return loop.publish_frames(250), op.telemetry.size() > 0; }, 60.0));
}

// Telemetry and status are open topics in the governance: any authenticated participant reads them. The
// parameter request topic needs a grant: an observer's permissions have none, so it cannot even create
// the writer.
TEST(DdsSecurity, AnAuthenticatedObserverReadsTelemetryButCannotWriteRequests) {
  ASSERT_FALSE(security_dir().empty()) << "scripts/dds_security.sh failed (openssl)";
  SecureLoop loop(test_domain(6));
  Collect<msg::Telemetry> telemetry;
  dds::Participant observer(loop.cfg.domain_id, config::DdsTransport::kUdpLoopback, "observer", identity("observer"));
  observer.reader(dds::TopicKind::kTelemetry, &telemetry);
  EXPECT_TRUE(eventually([&] { return loop.publish_frames(250), telemetry.size() > 0; }, 60.0));
  EXPECT_THROW((void)observer.writer(dds::TopicKind::kRequest), std::runtime_error) << "its permissions deny it";
  EXPECT_EQ(loop.handled.load(), 0);
}

// The dashboard joins a secured domain with the identity its configuration names: an operator's acts, an
// observer's only shows (its permissions grant neither the request writer nor the reply reader).
// ctest runs each test in a process of its own (gtest_discover_tests); run after the other security tests
// in one process, the fourth and fifth secured participants of the process do not discover each other
// over udp_loopback (Fast DDS 2.9 numbers participants per process and the initial peers cover the first few).
TEST(DdsSecurity, TheDashboardActsWithAnOperatorIdentityAndOnlyViewsWithAnObservers) {
  ASSERT_FALSE(security_dir().empty()) << "scripts/dds_security.sh failed (openssl)";
  SecureLoop loop(test_domain(7));
  config::DdsConfig op = loop.cfg;
  op.security = identity("operator");
  dashboard::Fleet fleet(op, 5.0);
  ASSERT_TRUE(eventually([&] { return loop.publish_frames(250), fleet.overview().size() == 1; }, 60.0));
  EXPECT_TRUE(fleet.view_only().empty());
  dashboard::RequestOutcome r;
  // Asked again while unanswered (the reply path may match after the first 2 s on a loaded machine): each
  // ask reaches the loop at most once, and the answered one did.
  int asked = 0;
  ASSERT_TRUE(eventually(
      [&] {
        return ++asked,
               (r = fleet.request(config::cell_name({}), dds::RequestKind::kSetGain, 2500.0, "alice", 2.0)).answered;
      },
      60.0));
  EXPECT_TRUE(r.accepted) << r.reason;
  const int handled = loop.handled.load();
  EXPECT_GE(handled, 1);
  EXPECT_LE(handled, asked);

  config::DdsConfig ob = loop.cfg;
  ob.security = identity("observer");
  dashboard::Fleet viewer(ob, 5.0);
  ASSERT_TRUE(eventually([&] { return loop.publish_frames(250), viewer.overview().size() == 1; }, 60.0))
      << viewer.counters().samples << " samples; " << viewer.view_only();
  EXPECT_FALSE(viewer.view_only().empty());
  r = viewer.request(config::cell_name({}), dds::RequestKind::kSetGain, 3000.0, "alice", 2.0);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.reason.find("may not write parameter requests"), std::string::npos) << r.reason;
  EXPECT_EQ(loop.handled.load(), handled);  // the observer's reached nothing
}

// Debian 12's Fast DDS 2.9.1 does not honour the governance's allow_unauthenticated_participants (Fast DDS
// added that in 2.11, eProsima/Fast-DDS#3385): an unauthenticated participant sees nothing of a secured
// loop, telemetry included, and nothing it writes reaches the bridge.
TEST(DdsSecurity, AnUnauthenticatedParticipantsRequestsNeverReachTheLoop) {
  ASSERT_FALSE(security_dir().empty()) << "scripts/dds_security.sh failed (openssl)";
  SecureLoop loop(test_domain(5));
  Client intruder(loop.cfg.domain_id);  // no security at all
  msg::ParameterRequest req;
  req.client("intruder");
  req.cell(config::cell_name({}));
  req.kind(msg::SET_GAIN);
  req.value(4000.0);
  for (std::uint32_t id = 1; id <= 30; ++id) {
    req.request_id(id);
    intruder.writer->write(&req);
    loop.publish_frames(250);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_FALSE(intruder.matched());
  EXPECT_EQ(loop.handled.load(), 0);
  EXPECT_EQ(loop.bridge->counters().requests, 0U);
  EXPECT_EQ(intruder.replies.size(), 0U);
  EXPECT_EQ(intruder.telemetry.size(), 0U) << "Fast DDS 2.9: no unauthenticated participant at all";
  // The positive control: the same secured loop, up all along, answers an authorised operator in the same domain;
  // so the intruder's silence is the security's doing, not a loop that never came up.
  Client op(loop.cfg.domain_id, identity("operator"));
  ASSERT_NO_FATAL_FAILURE(expect_operator_answered(loop, op, 100));  // the operator's 2500, not the intruder's 4000
  EXPECT_EQ(intruder.replies.size(), 0U);
}

TEST(DdsSecurity, TheSecuritySectionIsValidated) {
  std::string text = test::read_file(test::preset("horizontal_c2"));
  text += "dds:\n  security:\n    identity_ca: /nonexistent/ca.pem\n    identity_certificate: loop.pem\n";
  const std::string path = ::testing::TempDir() + "dds_security_bad_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text;
  try {
    (void)config::load_config_file(path);
    FAIL() << "accepted";
  } catch (const config::ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("dds.security.identity_ca = '/nonexistent/ca.pem': no such file"), std::string::npos) << w;
    EXPECT_NE(w.find("dds.security.private_key: missing"), std::string::npos) << w;
    EXPECT_NE(w.find("dds.security.permissions: missing"), std::string::npos) << w;
  }
}

}  // namespace
}  // namespace robodamp
