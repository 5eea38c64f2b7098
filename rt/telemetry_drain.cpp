#include "rt/telemetry_drain.hpp"

#include <cmath>

namespace robodamp::rt {

TelemetryDrain::TelemetryDrain(SpscRing<TelemetryFrame>& ring, std::vector<Consumer> consumers,
                               std::chrono::microseconds poll)
    : ring_(ring), consumers_(std::move(consumers)), poll_(poll) {}

TelemetryDrain::~TelemetryDrain() { stop(); }

void TelemetryDrain::start() {
  if (worker_.running()) return;
  worker_.start("rd-telemetry", [this](std::stop_token stop) {
    do {
      drain_all();
    } while (worker_.sleep_for(stop, poll_));
    drain_all();  // what the loop pushed before it stopped
  });
}

void TelemetryDrain::stop() { worker_.stop(); }

void TelemetryDrain::drain_all() {
  TelemetryFrame f;
  while (ring_.pop(f)) {
    for (auto& c : consumers_) c(f);
    frames_.fetch_add(1, std::memory_order_relaxed);
  }
}

void LiveTiming::operator()(const TelemetryFrame& f) {
  std::lock_guard lock(m_);
  s_.wake_latency.record(static_cast<std::int64_t>(std::llround(static_cast<double>(f.wake_latency_us) * 1e3)));
  s_.compute.record(static_cast<std::int64_t>(std::llround(static_cast<double>(f.compute_us) * 1e3)));
  s_.last = f;
  ++s_.frames;
}

LiveTiming::Snapshot LiveTiming::snapshot() const {
  std::lock_guard lock(m_);
  return s_;
}

}  // namespace robodamp::rt
