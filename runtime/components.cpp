#include "runtime/components.hpp"

#include <limits>

#include <unistd.h>

#include <chrono>

#include <spdlog/spdlog.h>

#include "drivers/can_channel.hpp"
#include "sim_plant/excitation.hpp"

namespace robodamp::runtime {

SimBackendComponent::SimBackendComponent(const sim::PlantModel& model, const config::Config& plant_cfg,
                                         drivers::SimBackendOptions o)
    : Component("simulated plant"), model_(model), cfg_(plant_cfg), o_(o) {}

Status SimBackendComponent::on_configure() {
  plant_ = std::make_unique<sim::Plant>(model_, cfg_);
  if (cfg_.disturbances.drives_on) plant_->add_excitation(sim::make_drive_vibration(model_, cfg_));
  backend_ = std::make_unique<drivers::SimBackend>(*plant_, o_);
  return {};
}

Status SimBackendComponent::on_cleanup() {
  backend_.reset();
  plant_.reset();
  return {};
}

CanBus::CanBus(const config::CanConfig& cfg, double rate_hz, config::ClockKind clock, double connect_timeout_s)
    : Component("CAN " + cfg.interface),
      cfg_(cfg),
      rate_hz_(rate_hz),
      clock_(clock),
      connect_timeout_s_(connect_timeout_s) {}

Status CanBus::on_configure() {
  driver_ = std::make_unique<drivers::CanDriver>(
      cfg_,
      drivers::CanChannel::open(cfg_.interface, cfg_.fd, cfg_.sensor.id, cfg_.sensor.extended_id, connect_timeout_s_),
      rate_hz_);
  // Lockstep with the emulator: a missing frame waits up to this long, then counts towards the stale trip.
  if (clock_ == config::ClockKind::kVirtual)
    driver_->set_lockstep_wait(1.0);
  else
    driver_->set_dejitter(true);
  return {};
}

CanBus::~CanBus() { stop_reconnecting(); }

Status CanBus::on_activate() {
  // A DAQ streams from power-up: what queued while the controller was starting is not a lost frame.
  if (clock_ == config::ClockKind::kWall) {
    flushed_ = driver_->flush();
    if (flushed_ > 0) spdlog::info("CAN: {} frames queued before the loop started, discarded", flushed_);
  }
  if (cfg_.interface.rfind("unix:", 0) == 0)
    reconnect_.start("rd-can-reconn", [this](std::stop_token stop) { reconnect_loop(stop); });
  return {};
}

void CanBus::reconnect_loop(std::stop_token stop) {
  const std::string path = cfg_.interface.substr(5);
  while (reconnect_.sleep_for(stop, std::chrono::milliseconds(20))) {
    if (const int fd = driver_->take_retired_fd(); fd >= 0) ::close(fd);
    if (!driver_->link_lost()) continue;
    try {
      drivers::CanChannel c = drivers::CanChannel::connect_unix(path, 0.05);
      if (driver_->offer_channel(std::move(c)))
        spdlog::warn("CAN: {} reconnected (the trip stays latched until reset)", cfg_.interface);
    } catch (const std::exception&) {
      // nobody listening yet: try again at the next round
    }
  }
}

void CanBus::stop_reconnecting() {
  reconnect_.stop();
  if (driver_)
    if (const int fd = driver_->take_retired_fd(); fd >= 0) ::close(fd);
}

Status CanBus::on_deactivate() {
  stop_reconnecting();
  return {};
}

Status CanBus::on_cleanup() {
  driver_.reset();  // closes the channel
  return {};
}

ModbusComponent::ModbusComponent(const config::ModbusConfig& cfg, config::Mounting initial,
                                 drivers::ModbusClient::MountingCallback on_mounting, double connect_timeout_s)
    : Component("Modbus " + config::describe(cfg.amplifier_link)),
      cfg_(cfg),
      initial_(initial),
      on_mounting_(std::move(on_mounting)),
      connect_timeout_s_(connect_timeout_s) {}

Status ModbusComponent::on_configure() {
  auto client = std::make_unique<drivers::ModbusClient>(cfg_, initial_, on_mounting_);
  std::lock_guard<std::mutex> lock(client_m_);
  client_ = std::move(client);
  return {};
}

void ModbusComponent::publish_advice(std::uint64_t seq, bool found, double rpm, double margin) {
  std::lock_guard<std::mutex> lock(client_m_);
  if (client_) client_->publish_advice(seq, found, rpm, margin);
}

void ModbusComponent::withdraw_advice(std::uint64_t seq) {
  std::lock_guard<std::mutex> lock(client_m_);
  if (client_) client_->withdraw_advice(seq);
}

double ModbusComponent::robot_depth_mm() const {
  std::lock_guard<std::mutex> lock(client_m_);
  return client_ ? client_->depth_mm() : std::numeric_limits<double>::quiet_NaN();
}

Status ModbusComponent::on_activate() {
  client_->start();
  answered_ = client_->wait_for_amplifier(std::chrono::duration<double>(connect_timeout_s_));
  // Not a failure: the link may come up later, and the arming policy reports the refusal if it never does.
  if (!answered_)
    spdlog::warn("Modbus: no answer from the amplifier ({}) within {} s; arming will wait for it",
                 config::describe(cfg_.amplifier_link), connect_timeout_s_);
  return {};
}

Status ModbusComponent::on_deactivate() {
  client_->request_amplifier_enable(false);
  client_->stop();  // writes the enable coil off when it can, then joins the polling threads
  return {};
}

Status ModbusComponent::on_cleanup() {
  std::unique_ptr<drivers::ModbusClient> client;
  {
    std::lock_guard<std::mutex> lock(client_m_);
    client = std::move(client_);
  }
  return {};  // destroyed here, outside the lock (it joins its threads)
}

DdsEndpoint::DdsEndpoint(const config::DdsConfig& cfg, double rate_hz, std::string source, dds::BridgeSources sources)
    : Component("DDS domain " + std::to_string(cfg.domain_id)),
      cfg_(cfg),
      rate_hz_(rate_hz),
      source_(std::move(source)),
      sources_(std::move(sources)) {}

Status DdsEndpoint::on_configure() {
  bridge_ = std::make_unique<dds::Bridge>(cfg_, rate_hz_, source_, sources_);
  return {};
}

Status DdsEndpoint::on_activate() {
  bridge_->start();
  spdlog::info("DDS: domain {} ({}), telemetry {} Hz, status {} Hz, parameter writes {}", cfg_.domain_id,
               config::to_string(cfg_.transport), cfg_.telemetry_rate_hz, cfg_.status_rate_hz,
               cfg_.parameter_writes ? "on" : "off");
  return {};
}

Status DdsEndpoint::on_deactivate() {
  bridge_->stop();
  return {};
}

Status DdsEndpoint::on_cleanup() {
  bridge_.reset();
  return {};
}

}  // namespace robodamp::runtime
