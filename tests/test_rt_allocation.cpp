// Proof that the real-time path allocates nothing and takes no lock: malloc, calloc, realloc,
// posix_memalign, aligned_alloc, memalign, valloc (and through them every form of new) and
// pthread_mutex_lock / trylock are interposed by counting versions, and the controller, the simulated
// plant, the CAN and Modbus drivers' real-time calls and the whole loop run with every RT-side operation
// exercised.
#include <gtest/gtest.h>

#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <new>
#include <thread>
#include <unistd.h>

#include "analysis/loop_model.hpp"
#include "analysis/modal_test.hpp"
#include "cell_util.hpp"
#include "rt/recording.hpp"
#include "rt/telemetry_drain.hpp"
#include "control/controller.hpp"
#include "drivers/can_driver.hpp"
#include "drivers/modbus_server.hpp"
#include "drivers/modbus_client.hpp"
#include "sim_plant/plant.hpp"
#include "test_util.hpp"

// Symbol interposition: this executable defines the C allocation functions and pthread_mutex_lock /
// trylock, so every call, from our code, libstdc++, yaml-cpp or Fast DDS, comes here first and is counted,
// then handed to glibc. new and new[] (plain, nothrow, aligned) reach malloc or aligned_alloc through
// libstdc++; the probes below check that each path is counted.
namespace {
std::atomic<long> g_allocations{0};
// Allocations and lock acquisitions on threads marked as the loop's (the real-time thread).
std::atomic<long> g_loop_thread_allocations{0};
std::atomic<long> g_loop_thread_locks{0};
thread_local bool t_loop_thread = false;
void count_allocation() noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (t_loop_thread) g_loop_thread_allocations.fetch_add(1, std::memory_order_relaxed);
}
void count_lock() noexcept {
  if (t_loop_thread) g_loop_thread_locks.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void* __libc_valloc(std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  count_allocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  count_allocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  count_allocation();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  count_allocation();
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(alignment, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  count_allocation();
  return __libc_memalign(alignment, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  count_allocation();
  return __libc_memalign(alignment, n);
}
void* valloc(std::size_t n) {
  count_allocation();
  return __libc_valloc(n);
}

using MutexFn = int (*)(pthread_mutex_t*);
int pthread_mutex_lock(pthread_mutex_t* m) {
  static const auto real = reinterpret_cast<MutexFn>(dlsym(RTLD_NEXT, "pthread_mutex_lock"));
  count_lock();
  return real(m);
}
int pthread_mutex_trylock(pthread_mutex_t* m) {
  static const auto real = reinterpret_cast<MutexFn>(dlsym(RTLD_NEXT, "pthread_mutex_trylock"));
  count_lock();
  return real(m);
}
}

namespace {

// Each allocation path and the lock are counted on a marked thread; nothing on an unmarked one.
TEST(RealTimePath, TheHooksCountEveryAllocationPathAndLock) {
  const long a0 = g_loop_thread_allocations.load(), l0 = g_loop_thread_locks.load();
  std::mutex m;
  t_loop_thread = true;
  void* p = std::malloc(24);
  p = std::realloc(p, 4096);
  void* q = std::calloc(3, 8);
  void* r = nullptr;
  const int rc = posix_memalign(&r, 64, 128);
  void* s = std::aligned_alloc(64, 128);
  void* t = ::operator new(16);
  void* u = ::operator new (16, std::align_val_t{64});
  void* v = ::operator new[](16, std::nothrow);
  m.lock();
  m.unlock();
  (void)m.try_lock();
  m.unlock();
  t_loop_thread = false;
  EXPECT_EQ(rc, 0);
  EXPECT_EQ(g_loop_thread_allocations.load() - a0, 8) << "malloc, realloc, calloc, posix_memalign, aligned_alloc, "
                                                         "new, aligned new, nothrow new[]";
  EXPECT_EQ(g_loop_thread_locks.load() - l0, 2) << "lock and try_lock";
  std::free(p), std::free(q), std::free(r), std::free(s);
  ::operator delete(t);
  ::operator delete (u, std::align_val_t{64});
  ::operator delete[](v);
  const long before = g_loop_thread_allocations.load();
  std::free(std::malloc(8));  // not a marked thread
  EXPECT_EQ(g_loop_thread_allocations.load(), before);
}

}  // namespace

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

// The CAN driver's read and write, with sensor frames, frames of other nodes, malformed datagrams, error
// frames, bus-off and restarts arriving, and the command frames read back by the peer.
TEST(RealTimePath, CanDriverAllocatesNothing) {
  config::CanConfig can;
  can.fd = true;
  can.sensor = {0x101, false, 8, {0, 4, true, config::ByteOrder::kLittle, 1e-5, 0.0}, config::CanCounter{4, 1}};
  can.command = {0x201, false, 8, {0, 2, true, config::ByteOrder::kBig, 1e-3, 0.0}, config::CanCounter{2, 1}};
  int sv[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  drivers::CanDriver driver(can, drivers::CanChannel::adopt(sv[0]), 5000.0);
  driver.set_dejitter(true, 500);  // as on the wall clock
  const long before = g_allocations.load(), locks_before = g_loop_thread_locks.load();
  t_loop_thread = true;
  double sink = 0.0;
  std::uint64_t ok_reads = 0;
  for (std::uint64_t tick = 0; tick < 200'000; ++tick) {
    const canfd_frame f = drivers::encode(can.sensor, true, std::sin(0.01 * static_cast<double>(tick)),
                                          static_cast<std::uint32_t>(tick + tick / 2000))
                              .frame;  // a gap every 0.4 s
    (void)send(sv[1], &f, CANFD_MTU, 0);
    canfd_frame extra = f;
    if (tick % 97 == 0) extra.can_id = 0x555;                                // another node
    if (tick % 5001 == 0) extra.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;      // bus-off ...
    if (tick % 5001 == 40) extra.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;  // ... and restart
    if (extra.can_id != f.can_id) (void)send(sv[1], &extra, CANFD_MTU, 0);
    if (tick % 331 == 0) (void)send(sv[1], &f, 9, 0);  // malformed datagram
    if (tick % 7 == 0) {                               // jitter: two frames in one tick, then none
      const canfd_frame g =
          drivers::encode(can.sensor, true, 0.0, static_cast<std::uint32_t>(tick + tick / 2000 + 1)).frame;
      (void)send(sv[1], &g, CANFD_MTU, 0);
    }
    const auto s = driver.read(tick);
    ok_reads += s.ok ? 1 : 0;
    sink += s.accel_mps2;
    (void)driver.write(0.001 * static_cast<double>(tick % 100), tick);
    canfd_frame out{};
    while (recv(sv[1], &out, sizeof out, MSG_DONTWAIT) > 0) sink += out.data[0];
  }
  t_loop_thread = false;
  EXPECT_EQ(g_allocations.load() - before, 0) << "allocations in the CAN driver";
  EXPECT_EQ(g_loop_thread_locks.load() - locks_before, 0) << "mutexes taken in the CAN driver";
  close(sv[1]);
  const auto k = driver.counters();
  EXPECT_GT(k.rx_frames, 190'000u);
  EXPECT_GT(k.bus_off, 30u);
  EXPECT_GT(k.rx_malformed, 500u);
  EXPECT_GT(k.lost_frames, 50u);
  EXPECT_GT(k.rx_held, 10000u);
  EXPECT_GT(ok_reads, 150'000u);
  EXPECT_TRUE(std::isfinite(sink));
}

// The Modbus client's real-time side: the loop asks for the enable and reads the status every tick;
// both are atomics (the polling threads are elsewhere). With the link down and up.
TEST(RealTimePath, ModbusStatusAllocatesNothing) {
  drivers::ModbusServer server;
  config::ModbusConfig m;
  m.amplifier_link.port = server.start("127.0.0.1", 0);
  m.poll_period_s = 0.002;
  drivers::ModbusClient sup(m, config::Mounting::kHorizontal);
  sup.start();
  ASSERT_TRUE(sup.wait_for_amplifier(std::chrono::seconds(5)));
  std::uint64_t faults = 0;
  const long before = g_loop_thread_allocations.load(), locks_before = g_loop_thread_locks.load();
  t_loop_thread = true;  // only this thread's allocations: the polling threads are not real-time
  const auto t0 = std::chrono::steady_clock::now();
  bool stopped = false;
  for (int i = 0; std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(400); ++i) {
    sup.request_amplifier_enable(i % 1000 < 500);
    faults += sup.amplifier_status().link_lost ? 1 : 0;
    if (!stopped && std::chrono::steady_clock::now() - t0 > std::chrono::milliseconds(100)) {
      t_loop_thread = false;
      server.stop();  // the link goes down: the status becomes unknown (the link lost while enabled)
      stopped = true;
      t_loop_thread = true;
    }
  }
  t_loop_thread = false;
  EXPECT_EQ(g_loop_thread_allocations.load() - before, 0) << "allocations in the Modbus client's real-time calls";
  EXPECT_EQ(g_loop_thread_locks.load() - locks_before, 0) << "mutexes taken in the Modbus client's real-time calls";
  sup.stop();
  EXPECT_GT(faults, 0U);
}

// The whole loop (sensor read, supervisor, controller, actuator write, amplifier I/O, telemetry push,
// timing) for a million ticks with the simulated backend, on the virtual clock, while the drain thread

// Runs the loop on this thread, marked as the loop's: what it allocated and locked.
struct LoopThreadCounts {
  long allocations{0}, locks{0};
};
LoopThreadCounts run_counted(rt::Loop& loop, std::uint64_t ticks) {
  const long before = g_loop_thread_allocations.load(), locks_before = g_loop_thread_locks.load();
  t_loop_thread = true;
  loop.run(ticks);
  t_loop_thread = false;
  return {g_loop_thread_allocations.load() - before, g_loop_thread_locks.load() - locks_before};
}
// records every frame to a file. Only the loop thread's allocations are counted: that is the RT thread.
TEST(RealTimePath, LoopWithSimulatedBackendAllocatesNothingOverAMillionTicks) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  runtime::Cell session(cfg, o);
  test::configure(session);
  auto& plant = session.plant();
  std::vector<double> hits;
  for (double t = 1.0; t < 200.0; t += 1.7) hits.push_back(t);
  plant.add_excitation(std::make_unique<sim::ImpactHammer>(0, 1000.0, 1e-3, hits));
  // Every supervisor path: trips, reset, re-arm, gain changes (accepted and refused), disarm (below).
  plant.faults().add({sim::FaultKind::kSensorSpike, 20.0, 0.001, 1e5});
  plant.faults().add({sim::FaultKind::kSensorDropout, 60.0, 0.01});
  plant.faults().add({sim::FaultKind::kAmplifierFault, 100.0, 0.01});
  plant.faults().add({sim::FaultKind::kActuatorSaturated, 140.0, 1.0, 0.002});

  // The session's own loop (armed at tick 51) and ring, driven here so that this thread is the loop's.
  rt::Loop& loop = session.loop();
  for (double t : {21.0, 61.0, 101.0, 142.0}) {
    loop.schedule(static_cast<std::uint64_t>(t * 5000), {rt::CommandKind::kResetFault, 0.0});
    loop.schedule(static_cast<std::uint64_t>((t + 0.1) * 5000), {rt::CommandKind::kArm, 0.0});
  }
  loop.schedule(30 * 5000, {rt::CommandKind::kSetGain, 3000.0});
  loop.schedule(31 * 5000, {rt::CommandKind::kSetGain, 1e9});
  loop.schedule(180 * 5000, {rt::CommandKind::kDisarm, 0.0});
  const std::string path = ::testing::TempDir() + "/alloc_loop.rec";
  rt::Recorder recorder(path, rt::recording_header({cfg.loop.rate_hz, cfg.source, cfg.yaml_text}, session.supervisor(),
                                                   config::ClockKind::kVirtual));
  rt::TelemetryDrain drain(session.telemetry_ring(), {[&](const rt::TelemetryFrame& f) { recorder.write(f); }});
  drain.start();

  const long probe = g_loop_thread_allocations.load();
  t_loop_thread = true;
  ::operator delete(::operator new(16));  // the hook counts on this thread
  t_loop_thread = false;
  ASSERT_EQ(g_loop_thread_allocations.load(), probe + 1);

  const LoopThreadCounts counts = run_counted(loop, 1'000'000);
  drain.stop();
  recorder.close();

  EXPECT_EQ(counts.locks, 0) << "mutexes taken on the loop thread";
  EXPECT_EQ(counts.allocations, 0) << "allocations on the loop thread";
  EXPECT_GE(loop.stats().ticks_run, 1'000'000U);
  EXPECT_EQ(recorder.frames(), loop.stats().ticks_run) << "every tick recorded";
  const auto& c = session.supervisor().counters();
  EXPECT_EQ(c.trips[static_cast<std::size_t>(rt::Trip::kSampleInvalid)], 1U);
  EXPECT_EQ(c.trips[static_cast<std::size_t>(rt::Trip::kSensorStale)], 1U);
  EXPECT_EQ(c.trips[static_cast<std::size_t>(rt::Trip::kAmplifierFault)], 1U);
  EXPECT_EQ(c.trips[static_cast<std::size_t>(rt::Trip::kSaturation)], 1U);
  EXPECT_EQ(c.gain_refused, 1U);
  // And the recording of all of it replays bit for bit.
  const rt::ReplayResult r = rt::replay(rt::read_recording(path));
  EXPECT_EQ(r.frames, loop.stats().ticks_run);
  EXPECT_EQ(r.mismatches, 0U);
}

// A loop scheduled by pose (config/presets/pose_scheduled_c2.yaml, the robot standing folded): the pose
// arrives, the loop arms, the pose moves to the stretched region and back (two hand-overs), then out of
// the map (a trip), a reset and the pose back: the loop thread allocates nothing and takes no lock, and
// the recording replays bit for bit.
TEST(RealTimePath, PoseScheduledLoopHandsOverAndTripsWithoutAllocating) {
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.arm_at_start = false;
  o.impact_every_s = 0.0;
  const config::Config cfg = config::load_config_file(test::preset("pose_scheduled_c2"));
  runtime::Cell session(cfg, o);
  test::configure(session);
  rt::Loop& loop = session.loop();
  const auto at = [](double t) { return static_cast<std::uint64_t>(t * 5000); };
  loop.schedule(1, {rt::CommandKind::kSetPoseRegion, 0.0});
  loop.schedule(at(0.5), {rt::CommandKind::kArm, 0.0});
  loop.schedule(at(3.0), {rt::CommandKind::kSetPoseRegion, 1.0});
  loop.schedule(at(12.0), {rt::CommandKind::kSetPoseRegion, 0.0});
  loop.schedule(at(21.0), {rt::CommandKind::kSetPoseRegion, -1.0});
  loop.schedule(at(22.0), {rt::CommandKind::kResetFault, 0.0});
  loop.schedule(at(22.1), {rt::CommandKind::kSetPoseRegion, 0.0});
  const std::string path = ::testing::TempDir() + "/alloc_pose.rec";
  rt::Recorder recorder(path, rt::recording_header({cfg.loop.rate_hz, cfg.source, cfg.yaml_text}, session.supervisor(),
                                                   config::ClockKind::kVirtual));
  rt::TelemetryDrain drain(session.telemetry_ring(), {[&](const rt::TelemetryFrame& f) { recorder.write(f); }});
  drain.start();
  const LoopThreadCounts counts = run_counted(loop, at(25.0));
  drain.stop();
  recorder.close();
  EXPECT_EQ(counts.locks, 0) << "mutexes taken on the loop thread";
  EXPECT_EQ(counts.allocations, 0) << "allocations on the loop thread";
  const auto& c = session.supervisor().counters();
  EXPECT_EQ(c.params_selected, 2U);
  EXPECT_EQ(c.pose_regions, 4U);
  EXPECT_EQ(c.pose_out_of_map, 1U);
  EXPECT_EQ(c.trips[static_cast<std::size_t>(rt::Trip::kPoseOutOfMap)], 1U);
  EXPECT_EQ(session.supervisor().state(), rt::State::kDisabled);
  const rt::ReplayResult r = rt::replay(rt::read_recording(path));
  EXPECT_EQ(r.mismatches, 0U);
}

// The spindle at 700 rpm from tick 100, the loop armed at tick 1000, 12 s on the loop thread: no lock, no allocation.
// A drain empties the telemetry ring as the cell's does: on the virtual clock the loop waits for it once it leads.
void expect_none_with_the_spindle_turning(runtime::Cell& session) {
  rt::Loop& loop = session.loop();
  loop.schedule(100, {rt::CommandKind::kSetSpindle, 700.0});
  loop.schedule(1000, {rt::CommandKind::kArm, 0.0});
  rt::TelemetryDrain drain(session.telemetry_ring(), {[](const rt::TelemetryFrame&) {}});
  drain.start();
  const LoopThreadCounts counts = run_counted(loop, 12 * 5000);
  drain.stop();
  EXPECT_EQ(counts.locks, 0) << "mutexes taken on the loop thread";
  EXPECT_EQ(counts.allocations, 0) << "allocations on the loop thread";
}

// The derating (supervision.derate): a loop unstable on its own (the actuator 3 x stronger than configured) with
// the spindle turning is probed, held at half gain, restored and probed again (then trips): no allocation, no lock.
TEST(RealTimePath, TheDeratingProbesHoldsAndRestoresWithoutAllocating) {
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.arm_at_start = false;
  o.impact_every_s = 0.0;
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  cfg.controller.speed_schedule.reset();
  config::Config real = cfg;
  real.actuator.constant_n_per_v *= 3.0;
  o.plant_config = real;
  runtime::Cell session(cfg, o);
  test::configure(session);
  expect_none_with_the_spindle_turning(session);
  const auto& c = session.supervisor().counters();
  EXPECT_GE(c.derate_probes, 2U);
  EXPECT_GE(c.growth_gain_fed, 1U);
  EXPECT_GE(c.derate_restores, 1U);
  EXPECT_GT(c.derated_ticks, 0U);
}

// The saturation's derating on the loop thread: a 400 N sine force at the TCP on the 9.2 Hz mode (an external
// force, as a deep cut's) with the spindle turning drives the actuator into its 36 N limit again and again.
// The first saturations (the arming's transient) derate at once, a later one is probed (the gain taken away,
// the window cleared), judged the process's and derated: nothing allocated, no lock taken.
TEST(RealTimePath, TheSaturationDeratingAllocatesNothing) {
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.arm_at_start = false;
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  cfg.controller.speed_schedule.reset();
  runtime::Cell session(cfg, o);
  test::configure(session);
  session.plant().add_excitation(std::make_unique<sim::Sine>(0, 400.0, 9.2, 0.0));  // at the TCP, on the 9.2 Hz mode
  expect_none_with_the_spindle_turning(session);
  const auto& c = session.supervisor().counters();
  std::printf(
      "[ rt path  ] saturation: %llu probes, %llu saturation derates, %llu restores, %llu saturated ticks, trip %s\n",
      static_cast<unsigned long long>(c.derate_probes), static_cast<unsigned long long>(c.saturation_derates),
      static_cast<unsigned long long>(c.derate_restores), static_cast<unsigned long long>(c.saturated_ticks),
      rt::to_string(session.supervisor().observed_trip()));
  EXPECT_GE(c.derate_probes, 1U);
  EXPECT_GE(c.growth_process, 1U);
  EXPECT_GE(c.saturation_derates, 2U);
  EXPECT_EQ(session.supervisor().observed_trip(), rt::Trip::kNone);
}

// robodamp measure's loop: the loop's chirp with K = 0 and the plant-side impact test
// (analysis::ModalTest on the simulated backend's step hook) through the whole commissioning plan: the
// loop thread allocates nothing and takes no lock.
TEST(RealTimePath, CommissioningMeasurementAllocatesNothing) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  cfg.commissioning.chirp_periods = 2, cfg.commissioning.chirp_period_s = 4.0;
  cfg.commissioning.impacts_per_location = 2, cfg.commissioning.record_s = 3.0;
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan plan = analysis::commissioning_plan(cfg, model);
  config::Config off = cfg;
  off.controller.gain_ns_per_m = 0.0;
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.chirp = {true,
             plan.chirp_start_s,
             cfg.commissioning.chirp_period_s,
             cfg.commissioning.chirp_periods,
             cfg.commissioning.chirp_f0_hz,
             cfg.commissioning.chirp_f1_hz,
             plan.chirp_amplitude_v};
  runtime::Cell session(off, o);
  test::configure(session);
  analysis::ModalTest modal(cfg, session.plant(), plan);
  struct Hook final : drivers::PlantStepHook {
    analysis::ModalTest* t;
    void before_step(std::uint64_t k) noexcept override { t->before_step(k); }
    void after_step(std::uint64_t k) noexcept override { t->after_step(k); }
  } hook;
  hook.t = &modal;
  session.sim_backend().set_step_hook(&hook);
  rt::Loop& loop = session.loop();
  loop.schedule(1, {rt::CommandKind::kArm, 0.0});
  rt::TelemetryDrain drain(session.telemetry_ring(), {[](const rt::TelemetryFrame&) {}});
  drain.start();
  const auto ticks = static_cast<std::uint64_t>(plan.duration_s * cfg.loop.rate_hz);
  const long before = g_loop_thread_allocations.load(), locks_before = g_loop_thread_locks.load();
  t_loop_thread = true;
  loop.run(ticks);
  t_loop_thread = false;
  const long during = g_loop_thread_allocations.load() - before;
  drain.stop();
  EXPECT_EQ(during, 0) << "allocations on the loop thread";
  EXPECT_EQ(g_loop_thread_locks.load() - locks_before, 0) << "mutexes taken on the loop thread";
  EXPECT_EQ(modal.records(), modal.records_planned());
  EXPECT_EQ(session.supervisor().latched_trip(), rt::Trip::kNone);
}

long resident_kib() {
  std::ifstream in("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  in >> pages_total >> pages_resident;
  return pages_resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// 60 s on the wall clock, set up for real time as `robodamp run` does, recording every tick: the loop
// thread allocates nothing, nothing is dropped, and the resident memory stays flat.
TEST(RealTimePath, SixtySecondRealTimeSoakHasAFlatMemoryFootprint) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  runtime::Cell session(cfg, {});
  test::configure(session);
  std::vector<double> hits;
  for (double t = 0.5; t < 60.0; t += 2.0) hits.push_back(t);
  session.plant().add_excitation(std::make_unique<sim::ImpactHammer>(0, 1000.0, 1e-3, hits));
  rt::Loop& loop = session.loop();  // wall clock (loop.clock), armed at tick 51
  const std::string path = ::testing::TempDir() + "/soak.rec";
  rt::Recorder recorder(path, rt::recording_header({cfg.loop.rate_hz, cfg.source, cfg.yaml_text}, session.supervisor(),
                                                   config::ClockKind::kWall));
  rt::LiveTiming live;
  rt::TelemetryDrain drain(session.telemetry_ring(),
                           {[&](const rt::TelemetryFrame& f) { recorder.write(f); }, std::ref(live)});
  rt::RealtimeStatus status;
  rt::RealtimeProcess process(cfg.realtime, status);
  drain.start();
  long loop_allocations = -1, loop_locks = -1;
  std::thread thread([&] {
    rt::setup_realtime_thread(cfg.realtime, status);
    const long before = g_loop_thread_allocations.load(), locks_before = g_loop_thread_locks.load();
    t_loop_thread = true;
    loop.run(60 * 5000);
    t_loop_thread = false;
    loop_allocations = g_loop_thread_allocations.load() - before;
    loop_locks = g_loop_thread_locks.load() - locks_before;
  });
  std::vector<long> rss;
  for (int i = 0; i < 13; ++i) {
    std::this_thread::sleep_for(std::chrono::seconds(5));
    rss.push_back(resident_kib());
  }
  thread.join();
  drain.stop();
  recorder.close();
  const auto stats = loop.stats();
  EXPECT_EQ(loop_allocations, 0);
  EXPECT_EQ(loop_locks, 0);
  EXPECT_EQ(stats.ring_drops, 0U);
  EXPECT_EQ(recorder.frames(), stats.ticks_run);
  // Timing on a shared machine is not this test's subject; anything else tripping is.
  const rt::Trip trip = session.supervisor().latched_trip();
  EXPECT_TRUE(trip == rt::Trip::kNone || trip == rt::Trip::kOverruns) << rt::to_string(trip);
  // Flat: from 5 s on, resident memory moves by less than 1 MiB.
  const auto [lo, hi] = std::minmax_element(rss.begin(), rss.end());
  EXPECT_LT(*hi - *lo, 1024) << "resident KiB from " << *lo << " to " << *hi;
  const auto snap = live.snapshot();
  std::printf(
      "[ soak     ] %llu ticks, missed %llu, overruns %llu; wake-up p50 %.0f p99 %.0f p99.9 %.0f max %.1f us; "
      "RSS %ld..%ld KiB; %s\n",
      static_cast<unsigned long long>(stats.ticks_run), static_cast<unsigned long long>(stats.missed_ticks),
      static_cast<unsigned long long>(stats.overruns), stats.wake_latency.percentile_us(0.5),
      stats.wake_latency.percentile_us(0.99), stats.wake_latency.percentile_us(0.999), stats.wake_latency.max_us(), *lo,
      *hi, status.fifo ? "SCHED_FIFO" : "SCHED_OTHER");
  EXPECT_EQ(snap.frames, stats.ticks_run) << "telemetry's timing view saw every tick";
}

}  // namespace
}  // namespace robodamp::control
