// Fast DDS: the loop's bridge publishing telemetry and status, and answering parameter requests, with
// subscriber and client participants in this process on UDP loopback (a domain of their own per run).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sys/wait.h>
#include <thread>
#include <vector>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "apps/session.hpp"
#include "dds/bridge.hpp"
#include "dds/participant.hpp"
#include "robodamp.h"
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
  explicit Client(int domain)
      : p(domain, config::DdsTransport::kUdpLoopback, "test client"),
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
    msg::ParameterRequest r;
    r.client("test");
    r.request_id(id);
    r.kind(kind);
    r.value(value);
    writer->write(&r);
    EXPECT_TRUE(eventually([&] {
      for (const auto& rep : replies.all())
        if (rep.request_id() == id) return true;
      return false;
    }));
    for (const auto& rep : replies.all())
      if (rep.request_id() == id) return rep;
    return {};
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
                     {"simulated plant", [] { return std::size_t{0}; }, [] { return 4324.0; },
                      [&](dds::RequestKind, double) {
                        ++handled;
                        return dds::Decision{true, ""};
                      }});
  bridge.start();
  Client client(cfg.domain_id);
  ASSERT_TRUE(eventually([&] { return client.matched(); }));
  // One second of loop frames: a 2 m/s^2 square wave's RMS, 3 ticks in 10 saturated, state active.
  for (std::uint64_t k = 0; k < 5000; ++k) {
    rt::TelemetryFrame f;
    f.tick = k;
    f.time_s = static_cast<double>(k) / 5000.0;
    f.accel_mps2 = (k % 2) ? 2.0 : -2.0;
    f.command_v = 0.5;
    f.gain_ns_per_m = 2000.0;
    f.state = static_cast<std::uint8_t>(rt::State::kActive);
    f.flags = (k % 10 < 3) ? rt::kFlagSaturated : 0;
    f.wake_latency_us = 12.0F;
    f.compute_us = 3.0F;
    bridge.on_frame(f);
    if (k % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(eventually([&] { return client.telemetry.size() >= 90; }));  // best effort: 100 sent
  const auto t = client.telemetry.last();
  EXPECT_NEAR(t.accel_rms_mps2(), 2.0, 1e-12);
  EXPECT_NEAR(t.saturated_fraction(), 0.3, 1e-6);
  EXPECT_DOUBLE_EQ(t.gain_ns_per_m(), 2000.0);
  ASSERT_TRUE(eventually([&] { return client.status.size() > 0 && client.status.last().tick() == 4999; }));
  const auto s = client.status.last();
  EXPECT_EQ(std::string(s.state()), "active");
  EXPECT_EQ(std::string(s.trip()), "none");
  EXPECT_EQ(std::string(s.backend()), "simulated plant");
  EXPECT_FALSE(s.parameter_writes());
  EXPECT_DOUBLE_EQ(s.max_gain_ns_per_m(), 4324.0);
  EXPECT_NEAR(s.wake_p99_us(), 12.0, 1.0);

  const auto reply = client.ask(1, msg::SET_GAIN, 2500.0);
  EXPECT_FALSE(reply.accepted());
  EXPECT_NE(std::string(reply.reason()).find("dds.parameter_writes is false in test.yaml"), std::string::npos) << reply.reason();
  EXPECT_EQ(handled, 0);
  bridge.stop();
  EXPECT_EQ(bridge.counters().refused, 1U);
}

TEST(Dds, ParameterRequestsAreValidatedLikeTheConfigurationAndApplied) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  config::DdsConfig d;
  d.domain_id = test_domain(2);
  d.transport = config::DdsTransport::kUdpLoopback;
  d.parameter_writes = true;
  cfg.dds = d;
  cfg.loop.clock = config::ClockKind::kWall;
  apps::SessionOptions o;
  o.realtime_setup = false;
  apps::Session session(cfg, o);
  session.add_parameter_set(config::load_config_file(test::preset("horizontal_c1")));
  apps::RunSummary summary;
  std::thread loop([&] { summary = session.run(6.0); });
  Client client(d.domain_id);
  ASSERT_TRUE(eventually([&] { return client.matched(); }));
  ASSERT_TRUE(eventually([&] { return client.status.size() > 0 && std::string(client.status.last().state()) == "active"; }));
  const double limit = client.status.last().max_gain_ns_per_m();
  EXPECT_NEAR(limit, cfg.supervision.max_gain_fraction * session.supervisor().parameter_sets()[0].max_stable_gain_ns_per_m, 1e-6);

  auto r = client.ask(1, msg::SET_GAIN, 90000.0);
  EXPECT_FALSE(r.accepted());
  EXPECT_NE(std::string(r.reason()).find("controller.gain_ns_per_m = 90000 N s/m is out of range"), std::string::npos) << r.reason();
  r = client.ask(2, msg::SET_GAIN, -1.0);
  EXPECT_FALSE(r.accepted());
  r = client.ask(3, msg::SELECT_PARAMETER_SET, 7.0);
  EXPECT_FALSE(r.accepted());
  EXPECT_NE(std::string(r.reason()).find("parameter_set = 7 is not a configured set"), std::string::npos) << r.reason();
  r = client.ask(4, msg::ENABLE, 2.0);
  EXPECT_FALSE(r.accepted());
  r = client.ask(5, msg::SET_GAIN, 2500.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually([&] { return client.telemetry.size() > 0 && client.telemetry.last().gain_ns_per_m() > 2499.0; }));
  r = client.ask(6, msg::SELECT_PARAMETER_SET, 1.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually([&] { return client.status.last().parameter_set() == 1; }));
  r = client.ask(7, msg::ENABLE, 0.0);
  EXPECT_TRUE(r.accepted()) << r.reason();
  ASSERT_TRUE(eventually([&] { return std::string(client.status.last().state()) == "disabled"; }));
  loop.join();
  ASSERT_TRUE(summary.dds.has_value());
  EXPECT_EQ(summary.dds->requests, 7U);
  EXPECT_EQ(summary.dds->refused, 4U);
  EXPECT_EQ(summary.supervisor.params_selected, 1U);
  EXPECT_EQ(summary.trip, "none");
}

// The command-line tools against a `robodamp run` process: the live view and a refused request.
TEST(Dds, MonitorShowsARunningLoopAndRequestSaysWhyItIsRefused) {
  const int domain = test_domain(3);
  const std::string dir = ::testing::TempDir() + "robodamp_dds_cli_" + std::to_string(getpid());
  std::system(("mkdir -p " + dir).c_str());
  std::string text = test::read_file(test::preset("horizontal_c2"));
  text += "\ndds:\n  domain_id: " + std::to_string(domain) + "\n  transport: udp_loopback\n  telemetry_rate_hz: 20\n";
  std::ofstream(dir + "/dds.yaml") << text;
  const std::string bin = ROBODAMP_BINARY;
  const std::string run = bin + " run --config " + dir + "/dds.yaml --duration 14 > " + dir + "/run.log 2>&1 &";
  ASSERT_EQ(std::system(run.c_str()), 0);
  const std::string monitor = bin + " monitor --config " + dir + "/dds.yaml --duration 4 > " + dir + "/monitor.log 2>&1";
  EXPECT_EQ(std::system(monitor.c_str()), 0) << test::read_file(dir + "/monitor.log");
  const std::string view = test::read_file(dir + "/monitor.log");
  EXPECT_NE(view.find("state      active"), std::string::npos) << view;
  EXPECT_NE(view.find("m/s^2 RMS"), std::string::npos) << view;
  EXPECT_NE(view.find("wake-up p50"), std::string::npos) << view;
  EXPECT_NE(view.find("parameter writes off"), std::string::npos) << view;
  const std::string request = bin + " request --config " + dir + "/dds.yaml --gain 2500 > " + dir + "/request.log 2>&1";
  const int rc = std::system(request.c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 3) << test::read_file(dir + "/request.log");
  EXPECT_NE(test::read_file(dir + "/request.log").find("refused: parameter writes are off"), std::string::npos);
  // The run ends on its own (its 14 s leave DDS discovery time for both clients on a loaded machine).
  EXPECT_TRUE(eventually([&] { return test::read_file(dir + "/run.log").find("state: disabled") != std::string::npos; }, 30.0))
      << test::read_file(dir + "/run.log");
}

}  // namespace
}  // namespace robodamp
