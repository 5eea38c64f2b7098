#include "drivers/can_channel.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/un.h>
#include <thread>
#include <chrono>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <system_error>
#include <unistd.h>

#include "rt/clock.hpp"

namespace robodamp::drivers {

namespace {
[[noreturn]] void fail(int fd, const std::string& what) {
  const int e = errno;
  if (fd >= 0) ::close(fd);
  throw std::system_error(e, std::generic_category(), what);
}
}  // namespace

CanChannel CanChannel::open_interface(const std::string& interface, bool fd_frames, std::uint32_t rx_id,
                                      bool rx_extended) {
  const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (s < 0) fail(-1, "CAN interface '" + interface + "': socket(PF_CAN, SOCK_RAW, CAN_RAW)");
  const int on = 1;
  if (fd_frames && ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0)
    fail(s, "CAN interface '" + interface + "': CAN_RAW_FD_FRAMES (does the interface support CAN FD?)");
  const can_filter filter{rx_id | (rx_extended ? CAN_EFF_FLAG : 0u),
                          (rx_extended ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG};
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
  if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
    fail(s, "CAN interface '" + interface + "': bind");
  return CanChannel(s, true);
}

namespace {
sockaddr_un unix_address(const std::string& path) {
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  if (path.size() >= sizeof a.sun_path)
    throw std::system_error(ENAMETOOLONG, std::generic_category(), "CAN transport unix:" + path);
  std::memcpy(a.sun_path, path.c_str(), path.size() + 1);
  return a;
}
}  // namespace

// The emulated bus queues about half a second of frames each way: SO_SNDBUF 1 MiB (the kernel doubles it, up
// to net.core.wmem_max) holds 2731 frames of 72 bytes where the default 208 KiB holds 278, 55 ms at 5 kHz, so a
// process the machine stalls for 100-130 ms (a loaded 2-core VM, measured) loses no frame and trips no queue.
// Best effort: a smaller wmem_max gives a shallower queue, not an error.
namespace {
void deep_queue(int fd) {
  const int bytes = 1 << 20;
  (void)::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
}
}  // namespace

CanChannel CanChannel::connect_unix(const std::string& path, double timeout_s) {
  const sockaddr_un a = unix_address(path);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (true) {
    const int s = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (s < 0) fail(-1, "CAN transport unix:" + path + ": socket");
    if (::connect(s, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0) {
      deep_queue(s);
      return CanChannel(s, false);
    }
    const int e = errno;
    ::close(s);
    if ((e != ENOENT && e != ECONNREFUSED) || std::chrono::steady_clock::now() >= end) {
      errno = e;
      fail(-1, "CAN transport unix:" + path + ": connect (is `robodamp plant` running?)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

CanChannel CanChannel::open(const std::string& interface, bool fd, std::uint32_t rx_id, bool rx_extended,
                            double connect_timeout_s) {
  if (interface.rfind("unix:", 0) == 0) return connect_unix(interface.substr(5), connect_timeout_s);
  return open_interface(interface, fd, rx_id, rx_extended);
}

bool CanChannel::wait_readable(std::int64_t timeout_ns) const noexcept {
  pollfd p{fd_, POLLIN, 0};
  const timespec ts{static_cast<time_t>(timeout_ns / 1'000'000'000), static_cast<long>(timeout_ns % 1'000'000'000)};
  return ::ppoll(&p, 1, &ts, nullptr) > 0;
}

CanListener::CanListener(const std::string& path) : path_(path) {
  const sockaddr_un a = unix_address(path);
  fd_ = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail(-1, "CAN transport unix:" + path + ": socket");
  ::unlink(path.c_str());  // a stale socket file of an emulator that died
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) < 0)
    fail(fd_, "CAN transport unix:" + path + ": bind");
  if (::listen(fd_, 1) < 0) fail(fd_, "CAN transport unix:" + path + ": listen");
}

CanListener::~CanListener() {
  if (fd_ >= 0) ::close(fd_);
  ::unlink(path_.c_str());
}

int CanListener::accept(double timeout_s) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout_s * 1000.0)) <= 0) return -1;
  const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (fd >= 0) deep_queue(fd);
  return fd;
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
  if (n == 0) return -ENOTCONN;                                              // a stream or SEQPACKET peer closed
  if (msg.msg_flags & MSG_TRUNC) return static_cast<int>(sizeof frame) + 1;  // larger than any CAN frame
  timestamp_ns = -1;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      timestamp_ns = ts.tv_sec * 1'000'000'000LL + ts.tv_nsec;
    }
  if (timestamp_ns < 0) timestamp_ns = rt::monotonic_ns();
  return static_cast<int>(n);
}

int CanChannel::send(const canfd_frame& frame, int bytes) noexcept {
  const ssize_t n = ::send(fd_, &frame, static_cast<std::size_t>(bytes), MSG_DONTWAIT | MSG_NOSIGNAL);
  if (n < 0) return -errno;
  return n == bytes ? 0 : -EIO;
}

}  // namespace robodamp::drivers
