#include "drivers/modbus_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <modbus/modbus.h>

namespace robodamp::drivers {

ModbusServer::ModbusServer(Sizes s) {
  map_ = modbus_mapping_new(s.coils, s.discrete_inputs, s.holding_registers, s.input_registers);
  if (map_ == nullptr) throw std::runtime_error(std::string("modbus_mapping_new: ") + modbus_strerror(errno));
}

ModbusServer::~ModbusServer() {
  stop();
  modbus_mapping_free(map_);
}

int ModbusServer::start(const std::string& host, int port) {
  if (worker_.running()) return port_;
  ctx_ = modbus_new_tcp(host.c_str(), port);
  if (ctx_ == nullptr)
    throw std::runtime_error("Modbus server " + host + ":" + std::to_string(port) + ": " + modbus_strerror(errno));
  listen_fd_ = modbus_tcp_listen(ctx_, 8);
  if (listen_fd_ < 0) {
    const std::string why = modbus_strerror(errno);
    modbus_free(ctx_);
    ctx_ = nullptr;
    throw std::runtime_error("Modbus server cannot listen on " + host + ":" + std::to_string(port) + ": " + why);
  }
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  worker_.start("rd-modbus-srv", [this](std::stop_token stop) { serve(stop); });
  return port_;
}

void ModbusServer::stop() {
  if (!worker_.running()) return;
  worker_.stop();
  for (int fd : clients_) close(fd);
  clients_.clear();
  close(listen_fd_);
  listen_fd_ = -1;
  modbus_free(ctx_);
  ctx_ = nullptr;
}

void ModbusServer::serve(std::stop_token stop) {
  std::vector<std::uint8_t> query(MODBUS_TCP_MAX_ADU_LENGTH);
  while (!stop.stop_requested()) {
    if (drop_.exchange(false)) {
      for (int fd : clients_) close(fd);
      clients_.clear();
    }
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(listen_fd_, &fds);
    int max_fd = listen_fd_;
    for (int fd : clients_) FD_SET(fd, &fds), max_fd = std::max(max_fd, fd);
    timeval tv{0, 20000};  // wake up to see stop() and drop_clients()
    if (select(max_fd + 1, &fds, nullptr, nullptr, &tv) <= 0) continue;
    if (FD_ISSET(listen_fd_, &fds)) {
      const int fd = accept(listen_fd_, nullptr, nullptr);
      if (fd >= 0) clients_.push_back(fd), ++connections_;
    }
    for (auto it = clients_.begin(); it != clients_.end();) {
      if (!FD_ISSET(*it, &fds)) {
        ++it;
        continue;
      }
      modbus_set_socket(ctx_, *it);
      const int rc = modbus_receive(ctx_, query.data());
      if (rc > 0) {
        ++requests_;
        if (responding_) {
          std::lock_guard<std::mutex> lock(m_);
          modbus_reply(ctx_, query.data(), rc, map_);
        }
      } else if (rc == -1) {  // closed by the client, or garbage
        close(*it);
        it = clients_.erase(it);
        continue;
      }
      ++it;
    }
  }
}

bool ModbusServer::coil(int a) const {
  std::lock_guard<std::mutex> lock(m_);
  return map_->tab_bits[a] != 0;
}
void ModbusServer::set_coil(int a, bool on) {
  std::lock_guard<std::mutex> lock(m_);
  map_->tab_bits[a] = on ? 1 : 0;
}
void ModbusServer::set_discrete_input(int a, bool on) {
  std::lock_guard<std::mutex> lock(m_);
  map_->tab_input_bits[a] = on ? 1 : 0;
}
void ModbusServer::set_input_register(int a, std::uint16_t v) {
  std::lock_guard<std::mutex> lock(m_);
  map_->tab_input_registers[a] = v;
}
std::uint16_t ModbusServer::holding_register(int a) const {
  std::lock_guard<std::mutex> lock(m_);
  return map_->tab_registers[a];
}
void ModbusServer::set_holding_register(int a, std::uint16_t v) {
  std::lock_guard<std::mutex> lock(m_);
  map_->tab_registers[a] = v;
}

}  // namespace robodamp::drivers
