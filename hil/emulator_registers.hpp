// The HIL emulator's Modbus side (hil/plant_emulator.hpp): the amplifier and the robot controller as
// libmodbus servers, one per distinct TCP port, with the registers of the configuration's modbus section
// (docs/hardware.md): what the emulated amplifier and robot publish, and the advice block robodamp run
// writes for the robot. Off the real-time path of the controller (the emulator's own loop).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "drivers/modbus_codec.hpp"
#include "drivers/modbus_server.hpp"

namespace robodamp::hil {

namespace modbus_codec = drivers::modbus_codec;

// The amplifier and the robot controller on Modbus: one server per distinct TCP port.
class EmulatorRegisters {
 public:
  explicit EmulatorRegisters(const config::Config& cfg) : m_(*cfg.modbus) {
    amp_ = std::make_unique<drivers::ModbusServer>();
    amp_->start(m_.amplifier_link.host, m_.amplifier_link.port);
    robot_ = amp_.get();
    if (m_.robot_link && m_.robot_link->port != m_.amplifier_link.port) {
      robot_server_ = std::make_unique<drivers::ModbusServer>();
      robot_server_->start(m_.robot_link->host, m_.robot_link->port);
      robot_ = robot_server_.get();
    }
    set_mounting(cfg.actuator.mounting);
  }
  [[nodiscard]] bool enable() const { return amp_->coil(m_.amplifier.enable_coil); }
  void set_spindle_rpm(double rpm) {
    if (m_.robot_link && m_.robot.spindle_rpm_register >= 0)
      robot_->set_holding_register(m_.robot.spindle_rpm_register,
                                   modbus_codec::encode_rpm(rpm, m_.robot.rpm_per_count));
  }
  // The depth the robot program cuts: unsigned counts of depth_mm_per_count; 65535 = not available.
  void set_depth_mm(double mm) {
    if (!m_.robot_link || m_.robot.depth_register < 0) return;
    robot_->set_holding_register(m_.robot.depth_register,
                                 modbus_codec::encode_depth_mm(mm, m_.robot.depth_mm_per_count));
  }
  // The advice block robodamp run writes (modbus.robot.advice_register): seq, rpm counts, margin x 100,
  // status; nothing without the block.
  [[nodiscard]] std::optional<std::array<std::uint16_t, 4>> advice() const {
    if (!m_.robot_link || m_.robot.advice_register < 0) return std::nullopt;
    std::array<std::uint16_t, 4> a{};
    for (int i = 0; i < 4; ++i) a[static_cast<std::size_t>(i)] = robot_->holding_register(m_.robot.advice_register + i);
    return a;
  }
  [[nodiscard]] double rpm_per_count() const { return m_.robot.rpm_per_count; }
  void set_ready(bool on) { amp_->set_discrete_input(m_.amplifier.ready_input, on); }
  void set_temperature(double c) {
    amp_->set_input_register(m_.amplifier.temperature_register,
                             modbus_codec::encode_temperature_c(c, m_.amplifier.temperature_c_per_count));
  }
  void set_mounting(config::Mounting m) {
    if (m_.robot_link)
      robot_->set_holding_register(
          m_.robot.mounting_register,
          static_cast<std::uint16_t>(m == config::Mounting::kVertical ? m_.robot.vertical_value
                                                                      : m_.robot.horizontal_value));
  }
  // The joint angles in the robot's registers: signed counts of deg_per_count; -32768 = not available.
  void set_joints(const std::vector<double>& q) {
    if (!m_.robot_link || m_.robot.joints_register < 0) return;
    for (std::size_t i = 0; i < q.size(); ++i)
      robot_->set_holding_register(m_.robot.joints_register + static_cast<int>(i),
                                   modbus_codec::encode_joint_deg(q[i], m_.robot.deg_per_count));
  }
  void hang() {
    amp_->set_responding(false);
    if (robot_server_) robot_server_->set_responding(false);
  }
  [[nodiscard]] std::uint64_t requests() const {
    return amp_->requests() + (robot_server_ ? robot_server_->requests() : 0);
  }
  [[nodiscard]] std::string describe() const {
    std::string s = "amplifier " + config::describe(m_.amplifier_link);
    if (m_.robot_link) s += ", robot " + config::describe(*m_.robot_link);
    return s;
  }

 private:
  config::ModbusConfig m_;
  std::unique_ptr<drivers::ModbusServer> amp_, robot_server_;
  drivers::ModbusServer* robot_{nullptr};
};

}  // namespace robodamp::hil
