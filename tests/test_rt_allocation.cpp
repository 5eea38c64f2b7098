// Proof that the real-time path allocates nothing: the global allocation functions are replaced by
// counting ones, and the controller runs over a million cycles with every RT-side operation exercised.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include "analysis/loop_model.hpp"
#include "control/controller.hpp"
#include "sim_plant/plant.hpp"
#include "test_util.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace robodamp::control {
namespace {

TEST(RealTimePath, ControllerAllocatesNothingOverAMillionCycles) {
  // Configure (may allocate): designs for two parameter sets.
  const auto c2 = test::design_preset("horizontal_c2");
  const auto c1 = test::design_preset("horizontal_c1");
  Controller c(c2.params);
  const ControllerParams next = c1.params;
  // Sanity: the hook counts.
  const long before_probe = g_allocations.load();
  ::operator delete(::operator new(16));  // a call, not a new-expression: never elided
  ASSERT_EQ(g_allocations.load(), before_probe + 1);

  const long before = g_allocations.load();
  double sink = 0.0;
  for (int i = 0; i < 1'200'000; ++i) {
    double x = 2.0 * std::sin(i * 0.0116) + 0.3;
    if (i % 100000 == 5) x = NAN;  // non-finite samples
    if (i % 77777 == 0) x = 1e4;   // saturating spikes
    if (i == 100000) (void)c.set_gain(1500.0);
    if (i == 300000) (void)c.request_params(next);
    if (i == 700000) c.reset(0.3);
    if (i == 800000) (void)c.set_gain(-1.0);  // refused
    sink += c.update(x);
  }
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0) << "allocations on the real-time path";
  EXPECT_TRUE(std::isfinite(sink));
  EXPECT_GT(c.counters().nonfinite_inputs, 0U);
  EXPECT_GT(c.counters().force_limited + c.counters().voltage_limited + c.counters().slew_limited, 0U);
  EXPECT_EQ(c.params().polarity, -1);  // the hand-over happened inside the counted window
}

TEST(RealTimePath, SimulatedPlantBackendAllocatesNothingOverAMillionCycles) {
  // The simulated plant is a backend the loop drives every tick: its step, sensor and faults too.
  const config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  const analysis::LoopModel model(cfg);
  sim::Plant plant(model.plant(), cfg);
  plant.add_excitation(sim::make_drive_vibration(model.plant(), cfg));
  plant.add_excitation(std::make_unique<sim::ImpactHammer>(0, 1000.0, 1e-3, std::vector<double>{1.0, 42.0, 150.0}));
  plant.add_excitation(std::make_unique<sim::Noise>(1, 1.0, 9, 5.0, 200.0, cfg.loop.rate_hz));
  plant.faults().add({sim::FaultKind::kSensorDropout, 20.0, 0.5});
  plant.faults().add({sim::FaultKind::kSensorNan, 30.0, 0.1});
  plant.faults().add({sim::FaultKind::kActuatorSaturated, 40.0, 5.0, 0.5});
  Controller c(model.chain().params);
  const long before = g_allocations.load();
  double command = 0.0, sink = 0.0;
  for (int i = 0; i < 1'000'000; ++i) {
    const sim::SensorReading r = plant.sense();
    const double next = c.update(r.accel_mps2);
    plant.step(command);
    command = next;
    sink += plant.acceleration_mps2(0) + plant.actuator_force_n() + plant.excitation_force_n(1);
  }
  EXPECT_EQ(g_allocations.load() - before, 0) << "allocations in the simulated backend's tick";
  EXPECT_TRUE(std::isfinite(sink));
  EXPECT_GT(plant.counters().force_limited, 0U);
}

}  // namespace
}  // namespace robodamp::control
