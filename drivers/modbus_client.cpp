#include "drivers/modbus_client.hpp"

#include "drivers/modbus_codec.hpp"
#include "rt/clock.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>

#include <modbus/modbus.h>
#include <spdlog/spdlog.h>

namespace robodamp::drivers {

namespace {

void set_timeout(modbus_t* ctx, double s) {
  const auto us = static_cast<std::uint32_t>(std::llround(s * 1e6));
  modbus_set_response_timeout(ctx, us / 1'000'000, us % 1'000'000);
  modbus_set_byte_timeout(ctx, us / 1'000'000, us % 1'000'000);
}

}  // namespace

ModbusLink::ModbusLink(const config::ModbusEndpoint& ep, const config::ModbusConfig& t)
    : ep_(ep),
      initial_(t.backoff_initial_s),
      max_(t.backoff_max_s),
      backoff_(t.backoff_initial_s),
      response_timeout_(t.response_timeout_s) {}

ModbusLink::~ModbusLink() {
  if (ctx_ != nullptr) {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
}

modbus_t* ModbusLink::connect(Clock::time_point now) {
  if (connected_) return ctx_;
  if (now < retry_at_) return nullptr;
  if (ctx_ == nullptr) {
    ctx_ = ep_.transport == config::ModbusTransport::kTcp
               ? modbus_new_tcp(ep_.host.c_str(), ep_.port)
               : modbus_new_rtu(ep_.device.c_str(), ep_.baud, ep_.parity, ep_.data_bits, ep_.stop_bits);
    if (ctx_ == nullptr) {
      last_error_ = modbus_strerror(errno);
      ++connect_failures;
      failed(now);
      return nullptr;
    }
    modbus_set_slave(ctx_, ep_.unit_id);
    set_timeout(ctx_, response_timeout_.count());
    modbus_set_error_recovery(ctx_, MODBUS_ERROR_RECOVERY_NONE);
  }
  if (modbus_connect(ctx_) == -1) {
    last_error_ = modbus_strerror(errno);
    ++connect_failures;
    failed(now);
    return nullptr;
  }
  connected_ = true;
  ++connects;
  return ctx_;
}

void ModbusLink::failed(Clock::time_point now) {
  if (connected_) {
    last_error_ = modbus_strerror(errno);
    if (errno == ETIMEDOUT) ++timeouts;
    ++errors;
    modbus_close(ctx_);
    connected_ = false;
  }
  retry_at_ = now + std::chrono::duration_cast<Clock::duration>(backoff_);
  backoff_ = std::min(backoff_ * 2.0, max_);
}

ModbusClient::ModbusClient(const config::ModbusConfig& cfg, config::Mounting initial, MountingCallback cb)
    : cfg_(cfg),
      on_mounting_(std::move(cb)),
      amp_link_(cfg.amplifier_link, cfg),
      mounting_(static_cast<int>(initial)),
      link_timeout_ns_(static_cast<std::int64_t>(cfg.link_timeout_s * 1e9)) {
  if (cfg_.robot_link) robot_link_.emplace(*cfg_.robot_link, cfg_);
}

ModbusClient::~ModbusClient() { stop(); }

void ModbusClient::start() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (running_) return;
    running_ = true;
  }
  amp_.start("rd-modbus-amp", [this](std::stop_token stop) { amplifier_thread(stop); });
  if (robot_link_) robot_.start("rd-modbus-robot", [this](std::stop_token stop) { robot_thread(stop); });
}

void ModbusClient::stop() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (!running_) return;
    running_ = false;
  }
  amp_seen_.notify_all();
  amp_.stop();
  robot_.stop();
}

bool ModbusClient::wait_for_amplifier(std::chrono::duration<double> timeout) const {
  std::unique_lock<std::mutex> lock(m_);
  return amp_seen_.wait_for(lock, timeout, [this] { return last_ok_ns_.load() >= 0 || !running_; }) &&
         last_ok_ns_.load() >= 0;
}

void ModbusClient::request_amplifier_enable(bool on) noexcept { requested_.store(on, std::memory_order_relaxed); }

rt::AmplifierStatus ModbusClient::amplifier_status() noexcept {
  rt::AmplifierStatus s;
  const std::int64_t last = last_ok_ns_.load(std::memory_order_acquire);
  const bool stale = last < 0 || rt::monotonic_ns() - last > link_timeout_ns_;
  const bool matters = requested_.load(std::memory_order_relaxed) || enabled_.load(std::memory_order_relaxed);
  if (stale) {
    // Unknown: harmless while the amplifier is off and not wanted; a fault otherwise.
    const bool fault = matters && last >= 0;
    if (fault && !link_fault_.exchange(true, std::memory_order_relaxed))
      link_faults_.store(link_faults_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    s.link_lost = fault;
    return s;
  }
  link_fault_.store(false, std::memory_order_relaxed);
  s.enabled = enabled_.load(std::memory_order_relaxed);
  s.ready = ready_.load(std::memory_order_relaxed);
  s.fault = fault_.load(std::memory_order_relaxed);
  s.temperature_c = temperature_c_.load(std::memory_order_relaxed);
  return s;
}

void ModbusClient::amplifier_thread(std::stop_token stop) {
  const auto& r = cfg_.amplifier;
  const int in_lo = std::min(r.ready_input, r.fault_input), in_n = std::abs(r.ready_input - r.fault_input) + 1;
  std::vector<std::uint8_t> inputs(static_cast<std::size_t>(in_n));
  const auto period = std::chrono::duration<double>(cfg_.poll_period_s);
  bool running = true;
  while (running) {
    const auto now = ModbusLink::Clock::now();
    modbus_t* ctx = amp_link_.connect(now);
    amp_up_.store(ctx != nullptr);
    if (ctx == nullptr) {
      running = amp_.sleep_for(stop, std::min<std::chrono::duration<double>>(period, amp_link_.retry_at() - now));
      continue;
    }
    const bool want = requested_.load(std::memory_order_relaxed);
    std::uint8_t coil = 0;
    std::uint16_t temp_raw = 0;
    bool ok = modbus_read_bits(ctx, r.enable_coil, 1, &coil) == 1;
    if (ok && (coil != 0) != want) {
      ok = modbus_write_bit(ctx, r.enable_coil, want ? 1 : 0) == 1;
      if (ok) coil = want ? 1 : 0, ++coil_writes_;
    }
    ok = ok && modbus_read_input_bits(ctx, in_lo, in_n, inputs.data()) == in_n;
    ok = ok && modbus_read_input_registers(ctx, r.temperature_register, 1, &temp_raw) == 1;
    if (!ok) {
      amp_link_.failed(ModbusLink::Clock::now());
      amp_up_.store(false);
      spdlog::warn("modbus amplifier {}: {} (reconnect in {:.3f} s)", config::describe(cfg_.amplifier_link),
                   amp_link_.last_error(), amp_link_.backoff().count() / 2.0);
      running = amp_.sleep_for(stop, std::chrono::duration<double>(0.0));
      continue;
    }
    amp_link_.succeeded();
    const double temp = modbus_codec::decode_temperature_c(temp_raw, r.temperature_c_per_count);
    enabled_.store(coil != 0, std::memory_order_relaxed);
    ready_.store(coil != 0 && inputs[static_cast<std::size_t>(r.ready_input - in_lo)] != 0, std::memory_order_relaxed);
    fault_.store(inputs[static_cast<std::size_t>(r.fault_input - in_lo)] != 0 || temp > r.temperature_max_c,
                 std::memory_order_relaxed);
    temperature_c_.store(temp, std::memory_order_relaxed);
    {
      std::lock_guard<std::mutex> lock(m_);
      last_ok_ns_.store(rt::monotonic_ns(), std::memory_order_release);
    }
    amp_seen_.notify_all();
    ++amp_polls_;
    running = amp_.sleep_for(stop, period);
  }
  // Leave the amplifier off: the loop has disarmed (or died); one last write if the link is up.
  if (modbus_t* ctx = amp_link_.connected() ? amp_link_.connect(ModbusLink::Clock::now()) : nullptr)
    modbus_write_bit(ctx, r.enable_coil, 0);
}

void ModbusClient::robot_thread(std::stop_token stop) {
  const auto& r = cfg_.robot;
  const auto period = std::chrono::duration<double>(cfg_.poll_period_s);
  int candidate = -1, same = 0;
  SpindleWatch spindle;
  PoseWatch pose;
  // A read on the robot's link failed: the link backs off, and the watched values are not known.
  auto read_failed = [&] {
    robot_link_->failed(ModbusLink::Clock::now());
    robot_up_.store(false);
    spdlog::warn("modbus robot {}: {}", config::describe(*cfg_.robot_link), robot_link_->last_error());
    candidate = -1, same = 0;
  };
  bool running = true;
  while (running) {
    const auto now = ModbusLink::Clock::now();
    modbus_t* ctx = robot_link_->connect(now);
    robot_up_.store(ctx != nullptr);
    if (ctx == nullptr || !poll_spindle(ctx, spindle) || !poll_pose(ctx, pose) || !poll_depth(ctx)) {
      if (ctx != nullptr) read_failed();  // the spindle, joint or depth registers' read failed
      park_spindle_if_lost(spindle);
      pose_unknown_if_lost(pose);
      depth_mm_.store(std::numeric_limits<double>::quiet_NaN());  // unknown while the link is down
      running = robot_.sleep_for(stop, std::min<std::chrono::duration<double>>(period, robot_link_->retry_at() - now));
      continue;
    }
    std::uint16_t v = 0;
    if (modbus_read_registers(ctx, r.mounting_register, 1, &v) != 1) {
      read_failed();
      park_spindle_if_lost(spindle);
      pose_unknown_if_lost(pose);
      running = robot_.sleep_for(stop, std::chrono::duration<double>(0.0));
      continue;
    }
    if (!write_advice(ctx)) {
      robot_link_->failed(ModbusLink::Clock::now());
      robot_up_.store(false);
      spdlog::warn("modbus robot {}: advice: {}", config::describe(*cfg_.robot_link), robot_link_->last_error());
      running = robot_.sleep_for(stop, std::chrono::duration<double>(0.0));
      continue;
    }
    robot_link_->succeeded();
    ++robot_polls_;
    int m = -1;
    if (v == r.horizontal_value)
      m = static_cast<int>(config::Mounting::kHorizontal);
    else if (v == r.vertical_value)
      m = static_cast<int>(config::Mounting::kVertical);
    else
      ++mounting_unknown_;
    same = m == candidate ? same + 1 : 1;
    candidate = m;
    if (m >= 0 && same >= r.settle_polls && m != mounting_.load()) {
      mounting_.store(m);
      ++mounting_changes_;
      spdlog::info("modbus robot: actuator mounting now {}", config::to_string(static_cast<config::Mounting>(m)));
      if (on_mounting_) on_mounting_(static_cast<config::Mounting>(m));
    }
    running = robot_.sleep_for(stop, period);
  }
}

void ModbusClient::publish_advice(std::uint64_t seq, bool found, double rpm, double margin) {
  if (cfg_.robot.advice_register < 0 || !robot_link_) return;
  const auto regs = modbus_codec::encode_advice(seq, found, rpm, margin, cfg_.robot.rpm_per_count);
  std::lock_guard<std::mutex> lock(m_);
  advice_regs_ = regs;
  advice_pending_ = true;
}

void ModbusClient::withdraw_advice(std::uint64_t seq) {
  if (cfg_.robot.advice_register < 0 || !robot_link_) return;
  std::lock_guard<std::mutex> lock(m_);
  advice_regs_ = modbus_codec::encode_withdrawn(seq);
  advice_pending_ = true;
}

bool ModbusClient::write_advice(modbus_t* ctx) {
  std::array<std::uint16_t, 4> regs{};
  {
    std::lock_guard<std::mutex> lock(m_);
    if (!advice_pending_) return true;
    regs = advice_regs_;
  }
  if (modbus_write_registers(ctx, cfg_.robot.advice_register, 4, regs.data()) != 4) return false;
  std::lock_guard<std::mutex> lock(m_);
  if (advice_regs_ == regs) advice_pending_ = false;  // a newer one waits for the next poll
  ++advice_writes_;
  return true;
}

bool ModbusClient::poll_depth(modbus_t* ctx) {
  const auto& r = cfg_.robot;
  if (r.depth_register < 0) return true;
  std::uint16_t v = 0;
  if (modbus_read_registers(ctx, r.depth_register, 1, &v) != 1) return false;
  const double mm = modbus_codec::decode_depth_mm(v, r.depth_mm_per_count);
  if (v == modbus_codec::kDepthUnavailable) ++depth_unavailable_polls_;
  const double was = depth_mm_.exchange(mm);
  if (!(mm == was) && !(std::isnan(mm) && std::isnan(was))) {
    ++depth_changes_;
    if (std::isnan(mm))
      spdlog::warn("modbus robot: depth not available (65535): the job's depth applies");
    else
      spdlog::info("modbus robot: cutting {:.3f} mm deep", mm);
  }
  return true;
}

bool ModbusClient::poll_spindle(modbus_t* ctx, SpindleWatch& w) {
  const auto& r = cfg_.robot;
  if (r.spindle_rpm_register < 0) return true;
  std::uint16_t v = 0;
  if (modbus_read_registers(ctx, r.spindle_rpm_register, 1, &v) != 1) return false;
  w.last_ok = ModbusLink::Clock::now();
  w.parked = false;
  w.same = static_cast<int>(v) == w.candidate ? w.same + 1 : 1;
  w.candidate = v;
  const double rpm = modbus_codec::decode_rpm(v, r.rpm_per_count);
  if (w.same >= r.settle_polls && rpm != w.rpm) {
    w.rpm = rpm;
    ++spindle_changes_;
    spdlog::info("modbus robot: spindle at {} rpm", rpm);
    if (on_spindle_) on_spindle_(rpm);
  }
  return true;
}

void ModbusClient::park_spindle_if_lost(SpindleWatch& w) {
  if (cfg_.robot.spindle_rpm_register < 0 || w.parked) return;
  w.candidate = -1, w.same = 0;
  if (ModbusLink::Clock::now() - w.last_ok < std::chrono::duration<double>(cfg_.link_timeout_s)) return;
  w.parked = true;
  w.rpm = 0.0;
  ++spindle_link_parks_;
  spdlog::warn("modbus robot: no spindle speed for {} s: the harmonic notches park", cfg_.link_timeout_s);
  if (on_spindle_) on_spindle_(0.0);
}

bool ModbusClient::poll_pose(modbus_t* ctx, PoseWatch& w) {
  const auto& r = cfg_.robot;
  if (r.joints_register < 0 || !schedule_) return true;
  constexpr std::size_t kMaxJoints = 16;
  const std::size_t n = std::min(schedule_->joints(), kMaxJoints);
  std::uint16_t regs[kMaxJoints] = {};
  if (modbus_read_registers(ctx, r.joints_register, static_cast<int>(n), regs) != static_cast<int>(n)) return false;
  w.last_ok = ModbusLink::Clock::now();
  w.lost = false;
  std::vector<double> q(n);
  bool available = true;
  for (std::size_t i = 0; i < n; ++i) {
    q[i] = modbus_codec::decode_joint_deg(regs[i], r.deg_per_count);
    if (std::isnan(q[i])) available = false;
  }
  {
    std::lock_guard lk(m_);
    joints_deg_ = q;
  }
  if (!available) ++pose_unavailable_polls_;
  const auto region = config::region_of(*schedule_, q.data(), n, w.settling.current());
  if (!region) ++pose_out_of_map_polls_;
  const long id = region ? static_cast<long>(*region) : -1;
  if (w.settling.settled(id, r.settle_polls)) report_pose(id);
  return true;
}

void ModbusClient::report_pose(long region) {
  ++pose_changes_;
  if (region >= 0)
    spdlog::info("modbus robot: pose in region '{}'", schedule_->regions[static_cast<std::size_t>(region)].name);
  else
    spdlog::warn("modbus robot: the pose is out of the map (outside every region of pose_schedule, or not available)");
  if (on_pose_) on_pose_(region >= 0 ? std::optional(static_cast<std::size_t>(region)) : std::nullopt);
}

void ModbusClient::pose_unknown_if_lost(PoseWatch& w) {
  if (cfg_.robot.joints_register < 0 || !schedule_ || w.lost) return;
  w.settling.restart();
  if (ModbusLink::Clock::now() - w.last_ok < std::chrono::duration<double>(cfg_.link_timeout_s)) return;
  w.lost = true;
  {
    std::lock_guard lk(m_);
    joints_deg_.clear();  // unknown, as the region
  }
  ++pose_link_losses_;
  spdlog::warn("modbus robot: no joint angles for {} s: the pose is unknown", cfg_.link_timeout_s);
  w.settling.reported = -1;
  report_pose(-1);
}

std::vector<double> ModbusClient::joints_deg() const {
  std::lock_guard lk(m_);
  return joints_deg_;
}

ModbusCounters ModbusClient::counters() const {
  ModbusCounters c;
  c.amplifier_polls = amp_polls_.load();
  c.robot_polls = robot_polls_.load();
  c.advice_writes = advice_writes_.load();
  c.depth_changes = depth_changes_.load();
  c.depth_unavailable_polls = depth_unavailable_polls_.load();
  for (const ModbusLink* l : {&amp_link_, robot_link_ ? &*robot_link_ : nullptr}) {
    if (l == nullptr) continue;
    c.connects += l->connects.load();
    c.connect_failures += l->connect_failures.load();
    c.errors += l->errors.load();
    c.timeouts += l->timeouts.load();
  }
  c.link_faults = link_faults_.load();
  c.coil_writes = coil_writes_.load();
  c.mounting_changes = mounting_changes_.load();
  c.mounting_unknown = mounting_unknown_.load();
  c.spindle_changes = spindle_changes_.load();
  c.spindle_link_parks = spindle_link_parks_.load();
  c.pose_changes = pose_changes_.load();
  c.pose_out_of_map_polls = pose_out_of_map_polls_.load();
  c.pose_unavailable_polls = pose_unavailable_polls_.load();
  c.pose_link_losses = pose_link_losses_.load();
  return c;
}

}  // namespace robodamp::drivers
