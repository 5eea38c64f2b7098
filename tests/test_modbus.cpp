// The Modbus supervisory client against a real libmodbus server on 127.0.0.1 (started here): the
// amplifier's enable coil, ready / fault / temperature, timeouts and disconnects with reconnect back-off,
// a lost link as a fault only when it matters, and the robot's mounting register with its settling.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include "drivers/modbus_codec.hpp"
#include "drivers/modbus_server.hpp"
#include "drivers/modbus_client.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

using drivers::ModbusClient;
using drivers::ModbusServer;
using test::eventually;

config::ModbusConfig client_config(int port) {
  config::ModbusConfig c;
  c.poll_period_s = 0.005;
  c.response_timeout_s = 0.05;
  c.backoff_initial_s = 0.02;
  c.backoff_max_s = 0.2;
  c.link_timeout_s = 0.1;
  c.amplifier_link.host = "127.0.0.1";
  c.amplifier_link.port = port;
  c.amplifier.enable_coil = 3;
  c.amplifier.ready_input = 4;
  c.amplifier.fault_input = 7;
  c.amplifier.temperature_register = 2;
  c.amplifier.temperature_c_per_count = 0.1;
  c.amplifier.temperature_max_c = 80.0;
  config::ModbusEndpoint robot = c.amplifier_link;
  robot.unit_id = 2;
  c.robot_link = robot;
  c.robot.mounting_register = 10;
  c.robot.horizontal_value = 0;
  c.robot.vertical_value = 1;
  c.robot.settle_polls = 3;
  return c;
}

// One register codec for the emulator's side and the client's: each value survives the round trip to
// its resolution, out-of-range values clamp, the "not available" codes decode as NaN.
TEST(Modbus, RegisterCodecRoundTripsClampsAndMarksUnavailable) {
  namespace mc = drivers::modbus_codec;
  EXPECT_DOUBLE_EQ(mc::decode_rpm(mc::encode_rpm(7234.0, 2.0), 2.0), 7234.0);
  EXPECT_EQ(mc::encode_rpm(-50.0, 1.0), 0U);
  EXPECT_EQ(mc::encode_rpm(1e9, 1.0), 65535U);
  EXPECT_NEAR(mc::decode_depth_mm(mc::encode_depth_mm(1.234, 0.001), 0.001), 1.234, 1e-12);
  EXPECT_EQ(mc::encode_depth_mm(1e9, 0.001), 65534U);  // the largest depth, never "not available"
  EXPECT_TRUE(std::isnan(mc::decode_depth_mm(mc::encode_depth_mm(std::nan(""), 0.001), 0.001)));
  EXPECT_NEAR(mc::decode_joint_deg(mc::encode_joint_deg(-123.45, 0.01), 0.01), -123.45, 1e-9);
  EXPECT_NEAR(mc::decode_joint_deg(mc::encode_joint_deg(-1e9, 0.01), 0.01), -327.67, 1e-9);  // never the NaN code
  EXPECT_TRUE(std::isnan(mc::decode_joint_deg(mc::encode_joint_deg(INFINITY, 0.01), 0.01)));
  EXPECT_NEAR(mc::decode_temperature_c(mc::encode_temperature_c(-12.5, 0.1), 0.1), -12.5, 1e-12);
  const auto a = mc::decode_advice(mc::encode_advice(70001, true, 6150.0, 1.37, 1.0), 1.0);
  EXPECT_EQ(a.seq, 70001U & 0xFFFFU);
  EXPECT_EQ(a.status, 1U);
  EXPECT_DOUBLE_EQ(a.rpm, 6150.0);
  EXPECT_DOUBLE_EQ(a.margin, 1.37);
  const auto none = mc::decode_advice(mc::encode_advice(3, false, 6150.0, 1.0, 1.0), 1.0);
  EXPECT_EQ(none.status, 2U);
  EXPECT_EQ(none.rpm, 0.0);
  EXPECT_EQ(mc::encode_advice(4, true, 100.0, INFINITY, 1.0)[2], 65535U);
}

TEST(Modbus, AmplifierEnableReadyFaultAndTemperature) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  server.set_input_register(2, 352);  // 35.2 degC
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal);
  sup.start();
  ASSERT_TRUE(sup.wait_for_amplifier(std::chrono::seconds(5)));
  rt::AmplifierStatus s = sup.amplifier_status();
  EXPECT_FALSE(s.enabled);
  EXPECT_FALSE(s.fault);
  EXPECT_NEAR(s.temperature_c, 35.2, 1e-9);

  sup.request_amplifier_enable(true);
  ASSERT_TRUE(eventually([&] { return server.coil(3); }));
  EXPECT_TRUE(eventually([&] { return sup.amplifier_status().enabled; }));
  EXPECT_FALSE(sup.amplifier_status().ready);  // enabled, not yet ready
  server.set_discrete_input(4, true);
  EXPECT_TRUE(eventually([&] { return sup.amplifier_status().ready; }));
  server.set_discrete_input(7, true);
  EXPECT_TRUE(eventually([&] { return sup.amplifier_status().fault; }));
  server.set_discrete_input(7, false);
  EXPECT_TRUE(eventually([&] { return !sup.amplifier_status().fault; }));
  server.set_input_register(2, 812);  // 81.2 degC: over temperature_max_c
  EXPECT_TRUE(eventually([&] { return sup.amplifier_status().fault; }));
  EXPECT_NEAR(sup.amplifier_status().temperature_c, 81.2, 1e-9);
  server.set_input_register(2, static_cast<std::uint16_t>(-50));  // -5.0 degC: signed
  EXPECT_TRUE(eventually([&] { return std::abs(sup.amplifier_status().temperature_c + 5.0) < 1e-9; }));

  // Someone else switches the amplifier off: the client writes the wanted state back.
  server.set_coil(3, false);
  EXPECT_TRUE(eventually([&] { return sup.counters().coil_writes >= 2 && server.coil(3); }));
  sup.request_amplifier_enable(false);
  EXPECT_TRUE(eventually([&] { return !server.coil(3); }));
  sup.stop();
  EXPECT_EQ(sup.counters().errors, 0U);
  EXPECT_EQ(sup.counters().link_faults, 0U);
}

// A hanging device: its status unknown while enabled is a lost link (the supervisor trips on the actuator
// path, which it may recover from), not a fault the amplifier reported.
TEST(Modbus, HangingDeviceTimesOutAndIsALostLinkWhileEnabled) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  server.set_discrete_input(4, true);
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal);
  sup.start();
  sup.request_amplifier_enable(true);
  ASSERT_TRUE(eventually([&] { return sup.amplifier_status().ready; }));

  server.set_responding(false);  // the device hangs: requests are read, never answered
  ASSERT_TRUE(eventually([&] { return sup.amplifier_status().link_lost; }));
  const auto status = sup.amplifier_status();
  EXPECT_FALSE(status.ready);
  EXPECT_FALSE(status.fault);
  EXPECT_TRUE(eventually([&] { return sup.counters().timeouts >= 1; }));
  EXPECT_EQ(sup.counters().link_faults, 1U);

  server.set_responding(true);  // back: reconnect, status known again
  EXPECT_TRUE(eventually([&] { return sup.amplifier_status().ready && !sup.amplifier_status().link_lost; }));
  EXPECT_GE(sup.counters().connects, 2U);
  sup.stop();
}

TEST(Modbus, LostLinkIsOnlyCountedWhileTheAmplifierIsNotNeeded) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal);
  sup.start();
  ASSERT_TRUE(sup.wait_for_amplifier(std::chrono::seconds(5)));
  server.stop();
  ASSERT_TRUE(eventually([&] { return !sup.amplifier_link_up(); }));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // past link_timeout_s
  const auto s = sup.amplifier_status();
  EXPECT_FALSE(s.fault);
  EXPECT_FALSE(s.link_lost);
  EXPECT_FALSE(s.ready);
  EXPECT_EQ(sup.counters().link_faults, 0U);
  // Asking for the amplifier while its state is unknown is a lost link.
  sup.request_amplifier_enable(true);
  EXPECT_TRUE(sup.amplifier_status().link_lost);
  EXPECT_EQ(sup.counters().link_faults, 1U);
  sup.stop();
}

TEST(Modbus, DisconnectReconnectsWithBackoff) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  auto cfg = client_config(port);
  cfg.robot_link.reset();
  ModbusClient sup(cfg, config::Mounting::kHorizontal);
  sup.start();
  ASSERT_TRUE(sup.wait_for_amplifier(std::chrono::seconds(5)));
  server.stop();  // the device goes away
  const auto down = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const auto failures = sup.counters().connect_failures;
  // Back-off 20, 40, 80, 160, 200, 200 ... ms: about 8 attempts in a second, never a busy loop.
  EXPECT_GE(failures, 3U);
  EXPECT_LE(failures, 12U);
  (void)down;
  ModbusServer again;
  again.start("127.0.0.1", port);  // the device is back on the same address
  again.set_input_register(2, 400);
  EXPECT_TRUE(eventually(
      [&] { return sup.amplifier_link_up() && std::abs(sup.amplifier_status().temperature_c - 40.0) < 1e-9; }));
  EXPECT_GE(sup.counters().connects, 2U);
  sup.stop();
}

TEST(Modbus, DroppedConnectionsReconnect) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal);
  sup.start();
  ASSERT_TRUE(sup.wait_for_amplifier(std::chrono::seconds(5)));
  // A poll answered on each link: the server has accepted both connections. (robot_link_up() is true once the
  // client's connect() returns, which the kernel completes before the server's accept(): a drop in between
  // left the robot's connection in the backlog, undropped, and only one link reconnected, once under load.)
  ASSERT_TRUE(eventually([&] { return sup.counters().robot_polls >= 1; }));
  const auto before = sup.counters().connects;
  server.drop_clients();
  EXPECT_TRUE(eventually([&] { return sup.counters().connects >= before + 2 && sup.amplifier_link_up(); }));
  EXPECT_GE(sup.counters().errors, 1U);
  sup.stop();
}

TEST(Modbus, RobotMountingSelectsAfterSettling) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  std::atomic<int> calls{0};
  std::atomic<int> last{-1};
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal, [&](config::Mounting m) {
    last = static_cast<int>(m);
    ++calls;
  });
  sup.start();
  ASSERT_TRUE(eventually([&] { return sup.counters().robot_polls >= 5; }));
  EXPECT_EQ(calls.load(), 0);          // horizontal, as configured
  server.set_holding_register(10, 7);  // neither value: counted, ignored
  ASSERT_TRUE(eventually([&] { return sup.counters().mounting_unknown >= 3; }));
  EXPECT_EQ(calls.load(), 0);
  server.set_holding_register(10, 1);
  ASSERT_TRUE(eventually([&] { return calls.load() == 1; }));
  EXPECT_EQ(last.load(), static_cast<int>(config::Mounting::kVertical));
  EXPECT_EQ(sup.mounting(), config::Mounting::kVertical);
  server.set_holding_register(10, 0);
  ASSERT_TRUE(eventually([&] { return calls.load() == 2; }));
  EXPECT_EQ(last.load(), static_cast<int>(config::Mounting::kHorizontal));
  sup.stop();
  EXPECT_EQ(sup.counters().mounting_changes, 2U);
}

// The spindle speed register (docs/harmonic_notch.md): scaled, handed over once settled, and a lost
// robot link parks the notches (speed 0) after modbus.link_timeout_s.
TEST(Modbus, SpindleRegisterSettlesScalesAndALostLinkParksTheNotches) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  config::ModbusConfig cfg = client_config(port);
  cfg.robot.spindle_rpm_register = 11;
  cfg.robot.rpm_per_count = 10.0;
  std::mutex m;
  std::vector<double> speeds;
  ModbusClient sup(cfg, config::Mounting::kHorizontal);
  sup.set_spindle_callback([&](double rpm) {
    std::lock_guard<std::mutex> lock(m);
    speeds.push_back(rpm);
  });
  auto seen = [&] {
    std::lock_guard<std::mutex> lock(m);
    return speeds;
  };
  server.set_holding_register(11, 1200);  // 12 000 rpm
  sup.start();
  ASSERT_TRUE(eventually([&] { return !seen().empty(); }));
  EXPECT_EQ(seen().front(), 12000.0);
  server.set_holding_register(11, 600);
  // The counters and the hand-over are updated one after the other on the poll thread: wait for both.
  ASSERT_TRUE(eventually([&] { return seen().size() == 2 && sup.counters().spindle_changes == 2U; }));
  EXPECT_EQ(seen().back(), 6000.0);
  server.stop();  // the robot controller goes away
  ASSERT_TRUE(eventually([&] { return sup.counters().spindle_link_parks == 1 && seen().size() == 3; }));
  EXPECT_EQ(seen().back(), 0.0);
  sup.stop();
}

// The depth the robot cuts (modbus.robot.depth_register): scaled; 65535 (the robot's "not available") and
// a lost link make it unknown (NaN: the job's depth applies), counted; nothing before the first poll.
TEST(Modbus, DepthRegisterScalesAndNotAvailableOrALostLinkIsUnknown) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  config::ModbusConfig cfg = client_config(port);
  cfg.robot.depth_register = 12;
  cfg.robot.depth_mm_per_count = 0.001;
  ModbusClient sup(cfg, config::Mounting::kHorizontal);
  EXPECT_TRUE(std::isnan(sup.depth_mm()));
  server.set_holding_register(12, 850);
  sup.start();
  ASSERT_TRUE(eventually([&] { return sup.depth_mm() == 0.85; }));
  server.set_holding_register(12, 65535);
  ASSERT_TRUE(eventually([&] { return std::isnan(sup.depth_mm()) && sup.counters().depth_unavailable_polls > 0; }));
  server.set_holding_register(12, 0);  // out of the cut
  ASSERT_TRUE(eventually([&] { return sup.depth_mm() == 0.0; }));
  EXPECT_EQ(sup.counters().depth_changes, 3U);
  server.stop();
  ASSERT_TRUE(eventually([&] { return std::isnan(sup.depth_mm()); }));
  sup.stop();
}

// The joint registers (pose_schedule): the region settles before it is handed over, the overlap keeps
// the region the pose is in, a register at -32768 (the robot's "not available") and a pose outside every
// region hand over "out of the map", and a lost link makes the pose unknown after link_timeout_s.
TEST(Modbus, JointRegistersSettleToARegionAndUnknownPosesAreOutOfTheMap) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  config::ModbusConfig cfg = client_config(port);
  cfg.robot.joints_register = 20;
  cfg.robot.deg_per_count = 0.01;
  config::PoseScheduleConfig schedule;
  schedule.workspace_min_deg = {-10.0, 0.0};
  schedule.workspace_max_deg = {10.0, 100.0};
  schedule.regions = {{"low", {-10.0, 0.0}, {10.0, 55.0}, {}, {}, {}, {}},
                      {"high", {-10.0, 45.0}, {10.0, 100.0}, {}, {}, {}, {}}};
  std::mutex m;
  std::vector<long> regions;  // -1: out of the map
  ModbusClient sup(cfg, config::Mounting::kHorizontal);
  sup.set_pose_callback(schedule, [&](std::optional<std::size_t> r) {
    std::lock_guard<std::mutex> lock(m);
    regions.push_back(r ? static_cast<long>(*r) : -1L);
  });
  auto seen = [&] {
    std::lock_guard<std::mutex> lock(m);
    return regions;
  };
  auto set_pose = [&](double q1, double q2) {
    server.set_holding_register(20, static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(q1 / 0.01))));
    server.set_holding_register(21, static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(q2 / 0.01))));
  };
  set_pose(-5.0, 30.0);
  sup.start();
  ASSERT_TRUE(eventually([&] { return seen().size() == 1; }));
  EXPECT_EQ(seen().back(), 0);
  EXPECT_TRUE(eventually([&] { return sup.joints_deg() == std::vector<double>{-5.0, 30.0}; }));
  set_pose(-5.0, 50.0);  // in the overlap: stays low
  set_pose(-5.0, 70.0);  // high
  ASSERT_TRUE(eventually([&] { return seen().size() == 2; }));
  EXPECT_EQ(seen().back(), 1);
  set_pose(-5.0, 50.0);  // in the overlap: stays high
  ASSERT_TRUE(eventually([&] { return sup.counters().robot_polls > 20 && sup.joints_deg().at(1) == 50.0; }));
  const auto polls = sup.counters().robot_polls;
  ASSERT_TRUE(eventually([&] { return sup.counters().robot_polls > polls + 5; }));
  EXPECT_EQ(seen().size(), 2u);
  server.set_holding_register(21, 0x8000);  // not available
  ASSERT_TRUE(eventually([&] { return seen().size() == 3; }));
  EXPECT_EQ(seen().back(), -1);
  EXPECT_GT(sup.counters().pose_unavailable_polls, 0u);
  EXPECT_TRUE(std::isnan(sup.joints_deg().at(1)));
  set_pose(-5.0, 20.0);
  ASSERT_TRUE(eventually([&] { return seen().size() == 4; }));
  EXPECT_EQ(seen().back(), 0);
  set_pose(50.0, 20.0);  // joint 1 outside the workspace
  ASSERT_TRUE(eventually([&] { return seen().size() == 5; }));
  EXPECT_EQ(seen().back(), -1);
  EXPECT_GT(sup.counters().pose_out_of_map_polls, 0u);
  set_pose(-5.0, 20.0);
  ASSERT_TRUE(eventually([&] { return seen().size() == 6; }));
  server.stop();  // the robot controller goes away
  ASSERT_TRUE(eventually([&] { return seen().size() == 7; }));
  EXPECT_EQ(seen().back(), -1);
  EXPECT_EQ(sup.counters().pose_link_losses, 1u);
  EXPECT_EQ(sup.counters().pose_changes, 7u);
  sup.stop();
}

TEST(Modbus, StopLeavesTheAmplifierOff) {
  ModbusServer server;
  const int port = server.start("127.0.0.1", 0);
  ModbusClient sup(client_config(port), config::Mounting::kHorizontal);
  sup.start();
  sup.request_amplifier_enable(true);
  ASSERT_TRUE(eventually([&] { return server.coil(3); }));
  sup.stop();
  EXPECT_FALSE(server.coil(3));
}

// A device that answers every request with garbage: random bytes, a header with another transaction id,
// a length that lies, an exception, half a reply, or a closed connection. On loopback, bounded in time,
// seeded.
class GarbageServer {
 public:
  explicit GarbageServer(std::uint64_t seed) : rng_(seed) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const int one = 1;
    setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    listen(fd_, 4);
    socklen_t len = sizeof a;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~GarbageServer() {
    stop_.store(true);
    thread_.join();
    for (int c : clients_) close(c);
    close(fd_);
  }
  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] int replies() const { return replies_.load(); }

 private:
  void serve() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);  // bounded whatever happens
    while (!stop_.load() && std::chrono::steady_clock::now() < end) {
      std::vector<pollfd> p{{fd_, POLLIN, 0}};
      for (int c : clients_) p.push_back({c, POLLIN, 0});
      if (poll(p.data(), p.size(), 20) <= 0) continue;
      if (p[0].revents & POLLIN) clients_.push_back(accept(fd_, nullptr, nullptr));
      for (std::size_t i = 1; i < p.size(); ++i) {
        if (!(p[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        unsigned char req[300];
        const ssize_t n = recv(p[i].fd, req, sizeof req, 0);
        if (n <= 0 || !answer(p[i].fd, req, static_cast<std::size_t>(n))) {
          close(p[i].fd);
          std::erase(clients_, p[i].fd);
        }
      }
    }
  }
  // false: the connection was closed on purpose.
  bool answer(int fd, const unsigned char* req, std::size_t n) {
    std::vector<unsigned char> r;
    auto random_bytes = [&](std::size_t k) {
      for (std::size_t i = 0; i < k; ++i) r.push_back(static_cast<unsigned char>(rng_() & 0xFF));
    };
    const unsigned char tid0 = n > 1 ? req[0] : 0, tid1 = n > 1 ? req[1] : 0, unit = n > 6 ? req[6] : 1;
    const unsigned char fn = n > 7 ? req[7] : 1;
    switch (rng_() % 7) {
      case 0:
        random_bytes(1 + rng_() % 40);
        break;
      case 1:
        r = {static_cast<unsigned char>(tid0 + 1), tid1, 0, 0, 0, 4, unit, fn, 1, 0xFF};
        break;  // another id
      case 2:
        r = {tid0, tid1, 0, 0, 0xFF, 0xFF, unit, fn, 1, 0xFF};
        break;  // length lies
      case 3:
        r = {tid0, tid1, 0, 0, 0, 3, unit, static_cast<unsigned char>(fn | 0x80), 4};
        break;  // exception
      case 4:
        r = {tid0, tid1, 0, 0, 0, 6, unit};
        break;  // half a reply
      case 5:
        return false;  // hang up
      default:
        r = {tid0, tid1, 0, 0, 0, 4, unit, fn, 9};
        random_bytes(2);
        break;  // byte count lies
    }
    ++replies_;
    return send(fd, r.data(), r.size(), MSG_NOSIGNAL) >= 0;
  }

  std::mt19937_64 rng_;
  int fd_{-1};
  int port_{0};
  std::vector<int> clients_;
  std::atomic<bool> stop_{false};
  std::atomic<int> replies_{0};
  std::thread thread_;
};

TEST(Modbus, ADeviceAnsweringGarbageIsCountedAndNeverReady) {
  GarbageServer server(11);
  ModbusClient sup(client_config(server.port()), config::Mounting::kHorizontal);
  sup.start();
  sup.request_amplifier_enable(true);
  bool ever_ready = false;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
    ever_ready = ever_ready || sup.amplifier_status().ready;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(eventually([&] { return server.replies() > 50; }, 20.0)) << server.replies();
  EXPECT_FALSE(ever_ready) << "garbage never reads as a ready amplifier";
  // Never one good poll: the status stays unknown (not ready, not enabled), so an arming supervisor
  // trips on amplifier_not_ready after supervision.amplifier_ready_timeout_s (test_rt_loop).
  EXPECT_FALSE(sup.amplifier_status().ready);
  EXPECT_FALSE(sup.amplifier_status().enabled);
  const auto c = sup.counters();
  EXPECT_GT(c.errors + c.timeouts + c.connect_failures, 10U);
  EXPECT_EQ(c.mounting_changes, 0U);
  sup.stop();
  std::printf("[ garbage  ] %d garbage replies: %llu errors, %llu timeouts, %llu connects, %llu link faults\n",
              server.replies(), static_cast<unsigned long long>(c.errors), static_cast<unsigned long long>(c.timeouts),
              static_cast<unsigned long long>(c.connects), static_cast<unsigned long long>(c.link_faults));
}

}  // namespace
}  // namespace robodamp
