// Telemetry plumbing: the SPSC ring across threads, the latency histogram, the recording format
// (header, frames, errors), CSV export and bit-exact replay.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <thread>

#include "cell_util.hpp"
#include "rt/recording.hpp"
#include "rt/spsc_ring.hpp"
#include "rt/timing_histogram.hpp"
#include "test_util.hpp"

namespace robodamp::rt {
namespace {

TEST(SpscRing, DeliversEveryItemInOrderAcrossThreads) {
  SpscRing<std::uint64_t> ring(1024);
  constexpr std::uint64_t kItems = 2'000'000;
  std::uint64_t dropped = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i)
      while (!ring.push(i)) ++dropped;  // retry: counts how often it was full
  });
  std::uint64_t expected = 0, v = 0;
  while (expected < kItems) {
    if (ring.pop(v)) {
      ASSERT_EQ(v, expected++);
    }
  }
  producer.join();
  EXPECT_FALSE(ring.pop(v));
}

TEST(SpscRing, FullRingRefusesWithoutOverwriting) {
  SpscRing<int> ring(4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(99));
  int v = -1;
  EXPECT_TRUE(ring.pop(v));
  EXPECT_EQ(v, 0);
  EXPECT_TRUE(ring.push(4));
  for (int i = 1; i <= 4; ++i) {
    EXPECT_TRUE(ring.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_THROW(SpscRing<int>(3), std::invalid_argument);
}

TEST(TimingHistogram, PercentilesInWholeMicrosecondsAndExactMax) {
  TimingHistogram h;
  for (int i = 0; i < 1000; ++i) h.record(i * 1000 + 400);  // 0.4 us .. 999.4 us
  h.record(20'000'000);                                     // 20 ms: overflow, max exact
  EXPECT_EQ(h.count(), 1001U);
  EXPECT_EQ(h.overflow(), 1U);
  EXPECT_DOUBLE_EQ(h.percentile_us(0.5), 500.0);
  EXPECT_DOUBLE_EQ(h.percentile_us(0.99), 990.0);
  EXPECT_DOUBLE_EQ(h.max_us(), 20000.0);
  EXPECT_EQ(h.bin(7), 1U);
}

class RecordingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "/rt_recording_" + std::to_string(::getpid()) + ".rec";
    runtime::CellOptions o;
    o.clock = config::ClockKind::kVirtual;
    o.record_path = path_;
    o.impact_every_s = 0.4;
    o.keep_frames = true;
    runtime::Cell session(config::load_config_file(test::preset("horizontal_c2")), o);
    test::configure(session);
    session.plant().faults().add({sim::FaultKind::kSensorNan, 1.2, 0.001});
    session.schedule(3000, {CommandKind::kSetGain, 2600.0});
    session.schedule(7000, {CommandKind::kResetFault, 0.0});
    session.schedule(7100, {CommandKind::kArm, 0.0});
    if (const runtime::Status st = session.run(2.0); !st.ok()) throw std::runtime_error(st.message);
    summary_ = session.summary();
    frames_ = session.frames();
  }
  std::string path_;
  runtime::RunSummary summary_;
  std::vector<TelemetryFrame> frames_;
};

TEST_F(RecordingTest, HeaderDescribesTheRunAndFramesAreWhatTheLoopPushed) {
  const Recording r = read_recording(path_);
  EXPECT_EQ(r.header.at("format"), "robodamp-recording");
  EXPECT_EQ(r.header.at("format_version"), kRecordingFormatVersion);
  EXPECT_EQ(r.header.at("frame_bytes"), sizeof(TelemetryFrame));
  EXPECT_EQ(r.header.at("clock"), "virtual");
  EXPECT_NE(r.header.at("config_yaml").get<std::string>().find("rate_hz"), std::string::npos);
  EXPECT_EQ(r.header.at("fields").size(), frame_fields().size());
  EXPECT_GT(r.header.at("controller_params").at("sections").size(), 3U);
  EXPECT_TRUE(r.header.at("supervisor").at("analysis_stable").get<bool>());
  ASSERT_EQ(r.frames.size(), frames_.size());
  EXPECT_EQ(std::memcmp(r.frames.data(), frames_.data(), frames_.size() * sizeof(TelemetryFrame)), 0);
  EXPECT_EQ(r.trailing_bytes, 0U);
  EXPECT_EQ(summary_.recorded_frames, summary_.loop.ticks_run);
}

TEST_F(RecordingTest, ReplayReproducesEveryCommandBitForBit) {
  const Recording r = read_recording(path_);
  const ReplayResult res = replay(r);
  EXPECT_EQ(res.frames, r.frames.size());
  EXPECT_EQ(res.mismatches, 0U);
  EXPECT_EQ(res.final_state, summary_.final_state);
  // The run had a trip, a reset, a re-arm and a gain change: replay went through all of them.
  EXPECT_EQ(summary_.supervisor.trips[static_cast<std::size_t>(Trip::kSampleInvalid)], 1U);
}

TEST_F(RecordingTest, ReplayDetectsAChangedSample) {
  Recording r = read_recording(path_);
  r.frames[4000].accel_mps2 += 1e-9;
  const ReplayResult res = replay(r);
  EXPECT_GT(res.mismatches, 0U);
  EXPECT_EQ(res.first_mismatch_tick, r.frames[4000].tick);
}

TEST_F(RecordingTest, TruncatedFileKeepsEveryWholeFrame) {
  const std::string cut = path_ + ".cut";
  {
    std::ifstream in(path_, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() - 50));
  }
  const Recording r = read_recording(cut);
  EXPECT_EQ(r.frames.size(), frames_.size() - 1);
  EXPECT_EQ(r.trailing_bytes, sizeof(TelemetryFrame) - 50);
  EXPECT_EQ(replay(r).mismatches, 0U);
}

TEST_F(RecordingTest, NotARecordingIsAClearError) {
  const std::string bad = path_ + ".bad";
  std::ofstream(bad) << "loop:\n  rate_hz: 5000\n";
  try {
    (void)read_recording(bad);
    FAIL() << "no error";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("not a robodamp recording"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)read_recording(path_ + ".missing"), RecordingError);
}

TEST_F(RecordingTest, CsvHasOneRowPerFrameAndExactValues) {
  const Recording r = read_recording(path_);
  const std::string csv = ::testing::TempDir() + "/rt_recording.csv";
  std::FILE* f = std::fopen(csv.c_str(), "w");
  write_csv(r, f);
  std::fclose(f);
  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("tick,time_s,dt_s,accel_mps2,filtered_mps,controller_v,command_v,", 0), 0U) << header;
  EXPECT_NE(header.find(",state_name,trip_name"), std::string::npos);
  std::size_t rows = 0;
  std::string row_6000;
  while (std::getline(in, line)) {
    if (rows == 6000) row_6000 = line;
    ++rows;
  }
  EXPECT_EQ(rows, r.frames.size());
  // command_v (7th column) parses back to the same double.
  std::stringstream ss(row_6000);
  std::string cell;
  for (int i = 0; i < 7; ++i) std::getline(ss, cell, ',');
  EXPECT_EQ(std::stod(cell), r.frames[6000].command_v);
}

// The file, not only the frames: a virtual-clock run's recording has no wall time in it (created_utc is
// null), so the same configuration, faults and commands give the same bytes.
TEST(Recording, AVirtualClockRecordingIsByteIdenticalRunToRun) {
  auto record = [](const std::string& path) {
    runtime::CellOptions o;
    o.clock = config::ClockKind::kVirtual;
    o.record_path = path;
    o.impact_every_s = 0.3;
    runtime::Cell cell(config::load_config_file(test::preset("horizontal_c2")), o);
    test::configure(cell);
    cell.plant().faults().add({sim::FaultKind::kSensorNan, 0.7, 0.001});
    cell.schedule(2000, {CommandKind::kSetGain, 2400.0});
    (void)cell.run(1.0);
    return test::read_file(path);
  };
  const std::string dir = ::testing::TempDir() + "/rt_identical_" + std::to_string(::getpid());
  const std::string a = record(dir + "_a.rec"), b = record(dir + "_b.rec");
  ASSERT_GT(a.size(), 5000U * sizeof(TelemetryFrame));
  EXPECT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "first differing byte at "
                      << std::distance(a.begin(), std::mismatch(a.begin(), a.end(), b.begin(), b.end()).first);
  EXPECT_NE(a.find("\"created_utc\":null"), std::string::npos);
}

}  // namespace
}  // namespace robodamp::rt
