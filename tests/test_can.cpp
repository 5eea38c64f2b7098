// The CAN link: signal codec, bus-load check, and the driver over a SEQPACKET socketpair carrying real
// struct can_frame / canfd_frame datagrams (this kernel has no CAN; the PF_CAN path is the same driver
// on a kernel socket). Error frames and bus-off are the frames the kernel would deliver.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <linux/can/error.h>
#include <random>
#include <sys/socket.h>
#include <system_error>
#include <unistd.h>

#include "config/config.hpp"
#include "drivers/can_driver.hpp"
#include "test_util.hpp"

namespace {

namespace cfg = robodamp::config;
using robodamp::drivers::CanChannel;
using robodamp::drivers::CanDriver;

cfg::CanConfig fd_link() {
  cfg::CanConfig c;
  c.fd = true;
  c.bitrate_bps = 1e6;
  c.data_bitrate_bps = 5e6;
  c.sensor.id = 0x101;
  c.sensor.length_bytes = 8;
  c.sensor.value = {0, 4, true, cfg::ByteOrder::kLittle, 1e-5, 0.0};
  c.sensor.counter = cfg::CanCounter{4, 1};
  c.command.id = 0x201;
  c.command.length_bytes = 8;
  c.command.value = {0, 2, true, cfg::ByteOrder::kBig, 1e-3, 0.0};
  c.command.counter = cfg::CanCounter{2, 1};
  c.lost_frames_fault = 5;
  c.backoff_initial_s = 0.01;
  c.backoff_max_s = 0.04;
  return c;
}

// Driver on one end of a socketpair; the test plays the bus on the other.
struct Link {
  explicit Link(const cfg::CanConfig& c, double rate_hz = 1000.0) {
    int sv[2];
    EXPECT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    peer = sv[1];
    driver = std::make_unique<CanDriver>(c, CanChannel::adopt(sv[0]), rate_hz);
  }
  ~Link() {
    if (peer >= 0) close(peer);
  }
  void send_sample(const cfg::CanConfig& c, double accel, std::uint32_t counter) const {
    const auto e = robodamp::drivers::encode(c.sensor, true, accel, counter);
    ASSERT_EQ(send(peer, &e.frame, static_cast<std::size_t>(e.frame_bytes), 0), e.frame_bytes);
  }
  void send_error(canid_t bits) const {
    can_frame f{};
    f.can_id = CAN_ERR_FLAG | bits;
    f.len = CAN_ERR_DLC;
    ASSERT_EQ(send(peer, &f, sizeof f, 0), static_cast<ssize_t>(sizeof f));
  }
  int peer{-1};
  std::unique_ptr<CanDriver> driver;
};

TEST(CanCodec, PacksAndUnpacksEveryLayout) {
  std::uint8_t d[8] = {};
  robodamp::drivers::pack_field(d, 1, 2, cfg::ByteOrder::kLittle, 0x1234);
  EXPECT_EQ(d[1], 0x34);
  EXPECT_EQ(d[2], 0x12);
  robodamp::drivers::pack_field(d, 4, 3, cfg::ByteOrder::kBig, 0xABCDEF);
  EXPECT_EQ(d[4], 0xAB);
  EXPECT_EQ(d[6], 0xEF);
  EXPECT_EQ(robodamp::drivers::unpack_field(d, 4, 3, false, cfg::ByteOrder::kBig), 0xABCDEF);
  EXPECT_EQ(robodamp::drivers::unpack_field(d, 4, 3, true, cfg::ByteOrder::kBig), 0xABCDEF - 0x1000000);
  for (int size = 1; size <= 4; ++size)
    for (bool is_signed : {true, false})
      for (auto order : {cfg::ByteOrder::kLittle, cfg::ByteOrder::kBig}) {
        cfg::CanFrameMapping m;
        m.id = 0x7FF;
        m.length_bytes = 8;
        m.value = {8 - size, size, is_signed, order, 0.5, -3.0};
        const double full = std::ldexp(1.0, 8 * size);
        for (double counts :
             {0.0, 1.0, is_signed ? -1.0 : 2.0, is_signed ? full / 2 - 1 : full - 1, is_signed ? -full / 2 : 7.0}) {
          const double value = counts * 0.5 - 3.0;
          const auto e = robodamp::drivers::encode(m, false, value, 0);
          EXPECT_FALSE(e.clipped) << size << is_signed;
          const auto dec = robodamp::drivers::decode(m, e.frame, e.frame_bytes);
          ASSERT_EQ(dec.error, robodamp::drivers::DecodeError::kNone);
          EXPECT_EQ(dec.value, value) << "size " << size << " signed " << is_signed;
        }
        // Out of range and NaN are clamped and flagged, never wrapped.
        const auto hi = robodamp::drivers::encode(m, false, 1e12, 0);
        EXPECT_TRUE(hi.clipped);
        EXPECT_GT(robodamp::drivers::decode(m, hi.frame, hi.frame_bytes).value, 0.0);
        EXPECT_TRUE(robodamp::drivers::encode(m, false, std::nan(""), 0).clipped);
      }
}

TEST(CanCodec, RejectsWhatDoesNotMatchTheMapping) {
  const auto c = fd_link();
  auto e = robodamp::drivers::encode(c.sensor, true, 1.0, 0);
  using robodamp::drivers::DecodeError;
  EXPECT_EQ(robodamp::drivers::decode(c.sensor, e.frame, CANFD_MTU).error, DecodeError::kNone);
  auto other = e.frame;
  other.can_id = 0x102;
  EXPECT_EQ(robodamp::drivers::decode(c.sensor, other, CANFD_MTU).error, DecodeError::kWrongId);
  auto extended = e.frame;
  extended.can_id = 0x101 | CAN_EFF_FLAG;
  EXPECT_EQ(robodamp::drivers::decode(c.sensor, extended, CANFD_MTU).error, DecodeError::kWrongId);
  auto shorter = e.frame;
  shorter.len = 4;
  EXPECT_EQ(robodamp::drivers::decode(c.sensor, shorter, CANFD_MTU).error, DecodeError::kShort);
  auto remote = e.frame;
  remote.can_id |= CAN_RTR_FLAG;
  EXPECT_EQ(robodamp::drivers::decode(c.sensor, remote, CANFD_MTU).error, DecodeError::kRemoteFrame);
  cfg::CanFrameMapping big = c.sensor;
  big.length_bytes = 16;
  EXPECT_EQ(robodamp::drivers::decode(big, e.frame, CAN_MTU).error, DecodeError::kNotFd);
}

// Random frames and payloads, and random datagrams through the driver: no crash, everything counted.
TEST(CanCodec, FuzzedFramesNeverCrashTheDecoderOrTheDriver) {
  std::mt19937_64 rng(12345);
  const auto c = fd_link();
  int decoded = 0;
  for (int i = 0; i < 1'000'000; ++i) {
    canfd_frame f{};
    f.can_id = static_cast<canid_t>(rng());
    if (i % 4 == 0) f.can_id = (f.can_id & ~(CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG | CAN_SFF_MASK)) | 0x101;
    f.len = static_cast<std::uint8_t>(rng());
    for (auto& b : f.data) b = static_cast<std::uint8_t>(rng());
    const int bytes = (rng() & 1) ? CAN_MTU : CANFD_MTU;
    const auto d = robodamp::drivers::decode(c.sensor, f, bytes);
    if (d.error == robodamp::drivers::DecodeError::kNone) {
      ++decoded;
      EXPECT_TRUE(std::isfinite(d.value));
    }
  }
  EXPECT_GT(decoded, 1000);
  Link link(c);
  std::uint64_t sent = 0;
  std::uint8_t buf[100];
  for (int i = 0; i < 20000; ++i) {
    const std::size_t n = 1 + rng() % sizeof buf;
    for (std::size_t k = 0; k < n; ++k) buf[k] = static_cast<std::uint8_t>(rng());
    if (i % 3 == 0) {
      canfd_frame f{};
      std::memcpy(&f, buf, std::min(n, sizeof f));
      f.can_id = 0x101;
      std::memcpy(buf, &f, std::min(n, sizeof f));
    }
    ASSERT_EQ(send(link.peer, buf, n, 0), static_cast<ssize_t>(n));
    ++sent;
    if (i % 16 == 0) (void)link.driver->read(static_cast<std::uint64_t>(i));
  }
  for (int i = 0; i < 1000; ++i) (void)link.driver->read(20000 + static_cast<std::uint64_t>(i));
  const auto k = link.driver->counters();
  EXPECT_EQ(k.rx_frames + k.rx_other + k.rx_malformed + k.error_frames + k.stale_frames, sent);
}

TEST(CanDriver, DecodesFreshSamplesAndCountsLostAndStaleFrames) {
  const auto c = fd_link();
  Link link(c);
  auto s = link.driver->read(0);
  EXPECT_FALSE(s.fresh) << "nothing sent yet";
  link.send_sample(c, 1.25, 7);
  s = link.driver->read(1);
  EXPECT_TRUE(s.fresh);
  EXPECT_TRUE(s.ok);
  EXPECT_NEAR(s.accel_mps2, 1.25, 1e-5);
  // A frame from another node is counted and ignored.
  auto other = robodamp::drivers::encode(c.command, true, 0.5, 0);
  ASSERT_GT(send(link.peer, &other.frame, CANFD_MTU, 0), 0);
  s = link.driver->read(2);
  EXPECT_FALSE(s.fresh);
  EXPECT_NEAR(s.accel_mps2, 1.25, 1e-5) << "the last value is held";
  // The DAQ repeats its counter: stale, not fresh.
  link.send_sample(c, 9.0, 7);
  s = link.driver->read(3);
  EXPECT_FALSE(s.fresh);
  EXPECT_NEAR(s.accel_mps2, 1.25, 1e-5);
  // Two frames lost, then five more within the second: the sensor driver is faulty.
  link.send_sample(c, 2.0, 10);
  s = link.driver->read(4);
  EXPECT_TRUE(s.fresh);
  EXPECT_TRUE(s.ok);
  link.send_sample(c, 2.0, 14);
  s = link.driver->read(5);
  EXPECT_FALSE(s.ok) << "5 lost frames within one second";
  // The counter wraps (8 bits) without a false loss.
  Link wrap(c);
  wrap.send_sample(c, 1.0, 255);
  wrap.send_sample(c, 1.0, 0);
  (void)wrap.driver->read(0);
  const auto k = link.driver->counters();
  EXPECT_EQ(wrap.driver->counters().lost_frames, 0u);
  EXPECT_EQ(k.rx_frames, 3u);
  EXPECT_EQ(k.rx_other, 1u);
  EXPECT_EQ(k.stale_frames, 1u);
  EXPECT_EQ(k.lost_frames, 5u);
  // Lost frames age out: two seconds later the sensor is healthy again.
  link.send_sample(c, 3.0, 15);
  s = link.driver->read(2005);
  EXPECT_TRUE(s.ok);
}

TEST(CanDriver, DejitterHoldsTheSecondOfTwoFramesAndResyncs) {
  const auto c = fd_link();
  Link link(c);
  link.driver->set_dejitter(true, 4);
  // Phases close: 2 frames in one tick, none in the next. Every tick gets a fresh sample, in order.
  std::uint32_t n = 0;
  link.send_sample(c, 1.0, n++);
  link.send_sample(c, 2.0, n++);
  auto s = link.driver->read(0);
  EXPECT_TRUE(s.fresh);
  EXPECT_NEAR(s.accel_mps2, 1.0, 1e-5);
  s = link.driver->read(1);
  EXPECT_TRUE(s.fresh) << "the held frame";
  EXPECT_NEAR(s.accel_mps2, 2.0, 1e-5);
  s = link.driver->read(2);
  EXPECT_FALSE(s.fresh) << "nothing held, nothing arrived";
  // Three at once: the oldest is skipped, the newest held.
  for (double v : {3.0, 4.0, 5.0}) link.send_sample(c, v, n++);
  s = link.driver->read(3);
  EXPECT_NEAR(s.accel_mps2, 4.0, 1e-5);
  // One frame per tick with one held: one period late, until resync_ticks (4) of it; then the newest.
  std::vector<double> got;
  for (int t = 0; t < 6; ++t) {
    link.send_sample(c, 6.0 + t, n++);
    s = link.driver->read(4 + t);
    EXPECT_TRUE(s.fresh);
    got.push_back(s.accel_mps2);
  }
  EXPECT_NEAR(got[0], 5.0, 1e-5);
  EXPECT_NEAR(got[2], 7.0, 1e-5);
  EXPECT_NEAR(got[3], 9.0, 1e-5) << "resynced to the newest";
  EXPECT_NEAR(got[5], 11.0, 1e-5) << "no longer late";
  const auto k = link.driver->counters();
  EXPECT_EQ(k.rx_frames, n);
  EXPECT_EQ(k.lost_frames, 0u);
  EXPECT_EQ(k.rx_skipped, 2u);
}

// A resync while the phases are still close costs a stale tick (the frame it skipped to was the one that
// would have covered the next tick without a frame); the driver then waits twice as long before the next.
TEST(CanDriver, DejitterBacksOffAResyncThatLeftATickWithoutAFrame) {
  const auto c = fd_link();
  Link link(c);
  link.driver->set_dejitter(true, 4);
  std::uint32_t n = 0;
  std::uint64_t tick = 0;
  std::uint64_t stale = 0;
  // The phases close for good: one frame per tick, every 7th tick none and the next two (jitter).
  auto step = [&](int frames) {
    for (int i = 0; i < frames; ++i) link.send_sample(c, static_cast<double>(n), n), ++n;
    if (!link.driver->read(tick++).fresh) ++stale;
  };
  step(2);  // one held from the start
  for (int cycle = 0; cycle < 60; ++cycle)
    for (int k = 0; k < 7; ++k) step(k == 5 ? 0 : k == 6 ? 2 : 1);
  const auto k = link.driver->counters();
  // The first resync (after 4 steady ticks) costs one stale tick; the interval doubles to 8, longer than
  // the 5 steady ticks the jitter allows, so no more. Without the back-off each of the 60 cycles lost one.
  EXPECT_EQ(stale, 1u);
  EXPECT_EQ(k.resync_backoffs, 1u);
  EXPECT_EQ(k.lost_frames, 0u);
}

TEST(CanDriver, SendsTheCommandFrameEveryCycleWithItsCounter) {
  const auto c = fd_link();
  Link link(c);
  for (std::uint64_t t = 0; t < 3; ++t) EXPECT_TRUE(link.driver->write(0.5 * static_cast<double>(t), t).ok);
  for (int t = 0; t < 3; ++t) {
    canfd_frame f{};
    ASSERT_EQ(recv(link.peer, &f, sizeof f, 0), CANFD_MTU);
    const auto d = robodamp::drivers::decode(c.command, f, CANFD_MTU);
    ASSERT_EQ(d.error, robodamp::drivers::DecodeError::kNone);
    EXPECT_NEAR(d.value, 0.5 * t, 1e-3);
    EXPECT_EQ(d.counter, static_cast<std::uint32_t>(t));
    EXPECT_EQ(f.data[0], t == 0 ? 0 : (t == 1 ? 0x01 : 0x03)) << "big-endian command";
  }
  const auto clipped = link.driver->write(100.0, 3);  // 16-bit field at 1 mV: +-32.767 V
  EXPECT_TRUE(clipped.ok);
  EXPECT_TRUE(clipped.saturated);
  EXPECT_EQ(link.driver->counters().tx_clipped, 1u);
}

TEST(CanDriver, ErrorFramesAndBusOffAreReportedAndRecoveredWithBackoff) {
  const auto c = fd_link();  // back-off 10 ms doubling to 40 ms, at 1 kHz
  Link link(c);
  link.send_sample(c, 1.0, 0);
  EXPECT_TRUE(link.driver->read(0).ok);
  link.send_error(CAN_ERR_CRTL);  // controller problem: counted, not a fault by itself
  EXPECT_TRUE(link.driver->read(1).ok);
  link.send_error(CAN_ERR_BUSOFF);
  const auto s = link.driver->read(2);
  EXPECT_FALSE(s.ok) << "bus-off is a sensor driver fault";
  EXPECT_TRUE(link.driver->bus_off());
  EXPECT_FALSE(link.driver->write(0.1, 2).ok) << "and an actuator driver fault";
  EXPECT_NEAR(link.driver->backoff_s(), 0.01, 1e-12);
  // The controller restarts: reception is healthy again, transmission waits out the back-off.
  link.send_error(CAN_ERR_RESTARTED);
  link.send_sample(c, 1.0, 1);
  EXPECT_TRUE(link.driver->read(3).ok);
  EXPECT_FALSE(link.driver->bus_off());
  EXPECT_FALSE(link.driver->write(0.1, 5).ok);
  EXPECT_TRUE(link.driver->write(0.1, 12).ok) << "retried after 10 ms";
  // Bus-off without a restart notice: the driver retries after the back-off on its own.
  link.send_error(CAN_ERR_BUSOFF);
  EXPECT_FALSE(link.driver->read(20).ok);
  EXPECT_TRUE(link.driver->write(0.1, 31).ok);
  const auto k = link.driver->counters();
  EXPECT_EQ(k.error_frames, 4u);
  EXPECT_EQ(k.bus_off, 2u);
  EXPECT_EQ(k.restarts, 1u);
  EXPECT_GE(k.tx_skipped, 2u);
}

TEST(CanDriver, AFullTransmitQueueBacksOffAndRecovers) {
  auto c = fd_link();
  Link link(c);
  // Fill the socket's queue: the driver sees what ENOBUFS is on PF_CAN (EAGAIN on a socketpair).
  int sent = 0;
  std::uint64_t t = 0;
  for (; t < 100000; ++t) {
    const auto st = link.driver->write(0.1, t);
    if (!st.ok) break;
    ++sent;
  }
  ASSERT_LT(t, 100000u) << "the queue never filled";
  const auto k = link.driver->counters();
  EXPECT_EQ(k.tx_queue_full, 3u) << "three consecutive full queues make the fault";
  EXPECT_NEAR(link.driver->backoff_s(), 0.01, 1e-12);
  // Still full after the back-off: it doubles, up to the maximum.
  t += 10;
  EXPECT_FALSE(link.driver->write(0.1, t).ok);
  EXPECT_FALSE(link.driver->write(0.1, t + 1).ok);
  EXPECT_FALSE(link.driver->write(0.1, t + 2).ok);
  // The bus drains: after the back-off the next command goes out.
  canfd_frame f{};
  while (recv(link.peer, &f, sizeof f, MSG_DONTWAIT) > 0) {}
  EXPECT_TRUE(link.driver->write(0.1, t + 100).ok);
  EXPECT_GT(sent, 10);
}

TEST(CanDriver, APeerThatHasGoneIsAFault) {
  const auto c = fd_link();
  Link link(c);
  link.send_sample(c, 1.0, 0);
  EXPECT_TRUE(link.driver->read(0).ok);
  close(link.peer);
  link.peer = -1;
  const auto s = link.driver->read(1);
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.fresh);
  EXPECT_TRUE(link.driver->link_lost());
  EXPECT_FALSE(link.driver->write(0.0, 1).ok || link.driver->write(0.0, 2).ok || link.driver->write(0.0, 3).ok);
}

TEST(CanDriver, ProductionOpensARawCanSocketOrSaysWhyNot) {
  try {
    const auto ch = CanChannel::open_interface("can0", true, 0x101, false);
    EXPECT_TRUE(ch.kernel_socket());
  } catch (const std::system_error& e) {
    // This kernel has no CAN (EAFNOSUPPORT) or no can0 (ENODEV): the message names the interface.
    EXPECT_NE(std::string(e.what()).find("CAN interface 'can0'"), std::string::npos) << e.what();
  }
}

// Bus load: frames per second x worst-case bits per frame against the bit rate.
TEST(CanConfig, BusLoadRejectsALoopRateTheBusCannotCarry) {
  std::string yaml = robodamp::test::read_file(robodamp::test::preset("horizontal_c2"));
  const std::string classic = R"(
can:
  interface: can0
  bitrate_bps: 1000000
  sensor:
    id: 0x101
    length_bytes: 8
    value: {start_byte: 0, size_bytes: 4, signed: true, byte_order: little, scale_mps2_per_count: 1.0e-5}
    counter: {start_byte: 4, size_bytes: 1}
  command:
    id: 0x201
    length_bytes: 8
    value: {start_byte: 0, size_bytes: 2, signed: true, byte_order: big, scale_v_per_count: 0.001}
)";
  try {
    (void)cfg::parse_config(yaml + classic, "hil.yaml");
    ADD_FAILURE() << "5 kHz on classic CAN at 1 Mbit/s with two 8-byte frames is 135 % of the bus";
  } catch (const cfg::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("loop.rate_hz: the bus cannot carry this loop: 5000 Hz x (135.0 us sensor + 135.0 us command"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("= 135 % of the bus at 1000 kbit/s"), std::string::npos) << m;
    EXPECT_NE(m.find("the highest loop rate is 2592 Hz"), std::string::npos) << m;
  }
  // The same frames on CAN FD with a 5 Mbit/s data phase fit.
  std::string fd = classic;
  fd.replace(fd.find("  bitrate_bps: 1000000\n"), 23,
             "  bitrate_bps: 1000000\n  fd: true\n  data_bitrate_bps: 5000000\n");
  const auto c = cfg::parse_config(yaml + fd, "hil.yaml");
  ASSERT_TRUE(c.can);
  EXPECT_LT(cfg::can_bus_load(*c.can, 5000.0), 0.7);
  EXPECT_EQ(c.can->sensor.id, 0x101u);
  // Bad mappings name the key.
  std::string bad = fd;
  bad.replace(bad.find("id: 0x201"), 9, "id: 0x901");
  bad.replace(bad.find("counter: {start_byte: 4"), 23, "counter: {start_byte: 2");
  try {
    (void)cfg::parse_config(yaml + bad, "hil.yaml");
    ADD_FAILURE();
  } catch (const cfg::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("can.command.id = '0x901' is not allowed: an identifier 0 <= id <= 0x7FF (11-bit)"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("can.sensor.counter: overlaps the value's bytes"), std::string::npos) << m;
  }
}

}  // namespace
