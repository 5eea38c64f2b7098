#include "drivers/can_channel.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <system_error>
#include <unistd.h>

namespace robodamp::drivers {

namespace {
[[noreturn]] void fail(int fd, const std::string& what) {
  const int e = errno;
  if (fd >= 0) ::close(fd);
  throw std::system_error(e, std::generic_category(), what);
}
}  // namespace

CanChannel CanChannel::open_interface(const std::string& interface, bool fd_frames, std::uint32_t rx_id, bool rx_extended) {
  const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (s < 0) fail(-1, "CAN interface '" + interface + "': socket(PF_CAN, SOCK_RAW, CAN_RAW)");
  const int on = 1;
  if (fd_frames && ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0)
    fail(s, "CAN interface '" + interface + "': CAN_RAW_FD_FRAMES (does the interface support CAN FD?)");
  const can_filter filter{rx_id | (rx_extended ? CAN_EFF_FLAG : 0u), (rx_extended ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG};
  if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) < 0) fail(s, "CAN_RAW_FILTER");
  const can_err_mask_t errors = CAN_ERR_MASK;
  if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors) < 0) fail(s, "CAN_RAW_ERR_FILTER");
  if (::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) < 0) fail(s, "SO_TIMESTAMPNS");
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) fail(s, "CAN interface '" + interface + "': no such interface");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) fail(s, "CAN interface '" + interface + "': bind");
  return CanChannel(s, true);
}

CanChannel& CanChannel::operator=(CanChannel&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.fd_;
    kernel_ = o.kernel_;
    o.fd_ = -1;
  }
  return *this;
}

CanChannel::~CanChannel() {
  if (fd_ >= 0) ::close(fd_);
}

int CanChannel::receive(canfd_frame& frame, std::int64_t& timestamp_ns) noexcept {
  iovec iov{&frame, sizeof frame};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
  if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -errno;
  if (n == 0) return -ENOTCONN;  // a stream or SEQPACKET peer closed
  if (msg.msg_flags & MSG_TRUNC) return static_cast<int>(sizeof frame) + 1;  // larger than any CAN frame
  timestamp_ns = -1;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      timestamp_ns = ts.tv_sec * 1'000'000'000LL + ts.tv_nsec;
    }
  if (timestamp_ns < 0) {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    timestamp_ns = ts.tv_sec * 1'000'000'000LL + ts.tv_nsec;
  }
  return static_cast<int>(n);
}

int CanChannel::send(const canfd_frame& frame, int bytes) noexcept {
  const ssize_t n = ::send(fd_, &frame, static_cast<std::size_t>(bytes), MSG_DONTWAIT | MSG_NOSIGNAL);
  if (n < 0) return -errno;
  return n == bytes ? 0 : -EIO;
}

}  // namespace robodamp::drivers
