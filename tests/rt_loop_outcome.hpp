// The loop tests' common ground: the default preset, a virtual-clock cell run to its end with every
// frame kept, and what to look for in the frames.
#pragma once

#include <stdexcept>

#include <gtest/gtest.h>

#include <vector>

#include "cell_util.hpp"
#include "config/config.hpp"
#include "runtime/cell.hpp"
#include "test_util.hpp"

namespace robodamp::rt {

using runtime::Cell;
using runtime::CellOptions;

inline config::Config c2() { return config::load_config_file(test::preset("horizontal_c2")); }

inline CellOptions virtual_clock() {
  CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.keep_frames = true;
  return o;
}

struct Outcome {
  runtime::RunSummary s;
  std::vector<TelemetryFrame> frames;
};

template <typename Setup>
inline Outcome run(const config::Config& cfg, double duration_s, Setup&& setup, CellOptions o = virtual_clock()) {
  Cell session(cfg, o);
  test::configure(session);
  setup(session);
  Outcome out;
  if (const runtime::Status st = session.run(duration_s); !st.ok()) throw std::runtime_error(st.message);
  out.s = session.summary();
  out.frames = session.frames();
  return out;
}
inline Outcome run(const config::Config& cfg, double duration_s, CellOptions o = virtual_clock()) {
  return run(
      cfg, duration_s, [](Cell&) {}, o);
}

// Every tick the loop ran reached the consumer, in order, none twice.
inline void expect_nothing_lost(const Outcome& r) {
  ASSERT_EQ(r.frames.size(), r.s.loop.ticks_run);
  EXPECT_EQ(r.s.loop.ring_drops, 0U);
  for (std::size_t i = 1; i < r.frames.size(); ++i) ASSERT_GT(r.frames[i].tick, r.frames[i - 1].tick) << i;
}

inline std::size_t first_state(const Outcome& r, State s, std::size_t from = 0) {
  for (std::size_t i = from; i < r.frames.size(); ++i)
    if (r.frames[i].state == static_cast<std::uint8_t>(s)) return i;
  return r.frames.size();
}

inline std::size_t first_state_after(const Outcome& r, State s, double t_s) {
  for (std::size_t i = 0; i < r.frames.size(); ++i)
    if (r.frames[i].time_s >= t_s && r.frames[i].state == static_cast<std::uint8_t>(s)) return i;
  return r.frames.size();
}

}  // namespace robodamp::rt
