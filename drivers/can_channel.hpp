// A CAN endpoint as a file descriptor: a raw PF_CAN socket bound to an interface (production), or any
// descriptor that carries struct can_frame / canfd_frame datagrams, one frame per read (a SEQPACKET
// socketpair in tests and to the HIL emulator, since this kernel has no CAN). Reads and writes are
// non-blocking (MSG_DONTWAIT), allocation-free and noexcept: safe on the real-time path.
#pragma once

#include <cstdint>
#include <linux/can.h>
#include <string>

namespace robodamp::drivers {

// The emulator's side of the UNIX transport: listens at a path (replacing a stale socket file) and
// accepts one controller at a time.
class CanListener {
 public:
  explicit CanListener(const std::string& path);  // throws std::system_error
  ~CanListener();
  CanListener(const CanListener&) = delete;
  CanListener& operator=(const CanListener&) = delete;
  // The next controller's connection, or -1 after timeout_s.
  [[nodiscard]] int accept(double timeout_s);
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_{-1};
};

class CanChannel {
 public:
  // PF_CAN raw socket on `interface`: FD frames when fd, kernel filter on rx_id (plus error frames, all
  // classes), kernel receive timestamps. Throws std::system_error naming the interface and the step.
  static CanChannel open_interface(const std::string& interface, bool fd, std::uint32_t rx_id, bool rx_extended);
  // Takes ownership of a descriptor carrying frames (socketpair).
  static CanChannel adopt(int fd) { return CanChannel(fd, false); }
  // The frame transport to a HIL emulator where there is no CAN: a UNIX SOCK_SEQPACKET socket at `path`,
  // connected to the emulator's listening socket (robodamp plant). Retries until timeout_s (the emulator
  // may still be starting); throws std::system_error naming the path.
  static CanChannel connect_unix(const std::string& path, double timeout_s);
  // can.interface "unix:PATH" -> connect_unix(PATH), anything else -> open_interface.
  static CanChannel open(const std::string& interface, bool fd, std::uint32_t rx_id, bool rx_extended,
                         double connect_timeout_s);

  CanChannel(CanChannel&& o) noexcept : fd_(o.fd_), kernel_(o.kernel_) { o.fd_ = -1; }
  CanChannel& operator=(CanChannel&& o) noexcept;
  CanChannel(const CanChannel&) = delete;
  CanChannel& operator=(const CanChannel&) = delete;
  ~CanChannel();

  // One frame if one is waiting: its size in bytes (CAN_MTU or CANFD_MTU, or what the datagram held),
  // 0 when none is waiting, -ENOTCONN when the peer has gone, else -errno. timestamp_ns: the kernel's
  // receive time (CLOCK_REALTIME) on PF_CAN, the read time (CLOCK_MONOTONIC) otherwise.
  [[nodiscard]] int receive(canfd_frame& frame, std::int64_t& timestamp_ns) noexcept;
  // 0 when queued, else -errno (-ENOBUFS or -EAGAIN: the transmit queue is full).
  [[nodiscard]] int send(const canfd_frame& frame, int bytes) noexcept;

  // Blocks up to timeout_ns for a frame (or the peer's close) to be readable: the lockstep pacing's
  // wait, never used on the wall clock. True when readable.
  [[nodiscard]] bool wait_readable(std::int64_t timeout_ns) const noexcept;

  [[nodiscard]] int fd() const noexcept { return fd_; }
  // Gives up the descriptor without closing it (the caller owns it now).
  [[nodiscard]] int release() noexcept {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  [[nodiscard]] bool kernel_socket() const noexcept { return kernel_; }

 private:
  CanChannel(int fd, bool kernel) : fd_(fd), kernel_(kernel) {}
  int fd_{-1};
  bool kernel_{false};
};

}  // namespace robodamp::drivers
