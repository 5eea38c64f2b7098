// The non-real-time side of the telemetry ring: a thread that pops frames and hands each to the
// consumers (recorder, live statistics, later DDS), polling at a fixed interval. The loop never waits
// for it on the wall clock: a full ring drops frames and the loop counts them.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <vector>

#include "rt/spsc_ring.hpp"
#include "rt/telemetry_frame.hpp"
#include "rt/timing_histogram.hpp"
#include "threads/worker.hpp"

namespace robodamp::rt {

class TelemetryDrain {
 public:
  using Consumer = std::function<void(const TelemetryFrame&)>;

  TelemetryDrain(SpscRing<TelemetryFrame>& ring, std::vector<Consumer> consumers,
                 std::chrono::microseconds poll = std::chrono::microseconds(1000));
  ~TelemetryDrain();
  TelemetryDrain(const TelemetryDrain&) = delete;
  TelemetryDrain& operator=(const TelemetryDrain&) = delete;

  void start();
  // Drains what is left, then joins.
  void stop();
  [[nodiscard]] std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }

 private:
  void drain_all();
  SpscRing<TelemetryFrame>& ring_;
  std::vector<Consumer> consumers_;
  std::chrono::microseconds poll_;
  std::atomic<std::uint64_t> frames_{0};
  threads::Worker worker_;  // last: stopped before the consumers go
};

// A consumer: the loop's timing as telemetry sees it (histograms of the frames' wake-up latency and
// compute time), with the latest frame, for a live view while the loop runs.
class LiveTiming {
 public:
  void operator()(const TelemetryFrame& f);
  struct Snapshot {
    TimingHistogram wake_latency;
    TimingHistogram compute;
    TelemetryFrame last{};
    std::uint64_t frames{0};
  };
  [[nodiscard]] Snapshot snapshot() const;

 private:
  mutable std::mutex m_;
  Snapshot s_;
};

}  // namespace robodamp::rt
