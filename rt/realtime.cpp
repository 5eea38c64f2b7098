#include "rt/realtime.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

#include <spdlog/spdlog.h>

namespace robodamp::rt {

namespace {
// Each fallback is one warning, logged when it happens (before activation) and kept for the summary.
void warn(RealtimeStatus& status, std::string text) {
  spdlog::warn("real-time set-up: {}", text);
  status.warnings.push_back(std::move(text));
}

std::string err(int e) { return std::string(std::strerror(e)) + " (errno " + std::to_string(e) + ")"; }

// Touches the stack below the current frame so its pages are mapped (and locked) before activation.
__attribute__((noinline)) void prefault_stack(std::size_t bytes) {
  volatile unsigned char* p = static_cast<volatile unsigned char*>(alloca(bytes));
  for (std::size_t i = 0; i < bytes; i += 4096) p[i] = 0;
}
// A sanitizer build (scripts/sanitize.sh) maps terabytes of shadow memory: mlockall would try to lock it.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizerShadow = true;
#else
constexpr bool kSanitizerShadow = false;
#endif
}  // namespace

RealtimeProcess::RealtimeProcess(const RealtimeSettings& c, RealtimeStatus& status) {
  if (c.lock_memory && kSanitizerShadow) {
    warn(status, "a sanitizer build: memory not locked (its shadow mappings are terabytes); pages may fault");
  } else if (c.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      locked_ = status.memory_locked = true;
    } else {
      warn(status, "mlockall failed: " + err(errno) +
                       "; pages may fault during the run. Run as root, or raise the memlock limit "
                       "(`ulimit -l unlimited`, LimitMEMLOCK=infinity in the systemd unit)");
    }
  }
  if (c.hold_cpu_dma_latency) {
    dma_fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    const std::int32_t zero = 0;
    if (dma_fd_ >= 0 && ::write(dma_fd_, &zero, sizeof zero) == static_cast<ssize_t>(sizeof zero)) {
      status.dma_latency_held = true;
    } else {
      const int e = errno;
      if (dma_fd_ >= 0) ::close(dma_fd_);
      dma_fd_ = -1;
      warn(status, "cannot hold /dev/cpu_dma_latency at 0: " + err(e) +
                       "; deep C-states may add wake-up latency. Run as root or grant write access "
                       "to /dev/cpu_dma_latency (or set realtime.hold_cpu_dma_latency: false)");
    }
  }
}

RealtimeProcess::~RealtimeProcess() {
  if (dma_fd_ >= 0) ::close(dma_fd_);  // closing releases the latency request
  if (locked_) munlockall();
}

void setup_realtime_thread(const RealtimeSettings& c, RealtimeStatus& status) {
  if (c.priority > 0) {
    sched_param sp{};
    sp.sched_priority = c.priority;
    const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (e == 0) {
      status.fifo = true;
      status.priority = c.priority;
    } else {
      warn(status, "SCHED_FIFO priority " + std::to_string(c.priority) + " not permitted: " + err(e) +
                       "; the loop runs SCHED_OTHER and its latency will suffer. Run as root, or give "
                       "the user an rtprio limit (`@robodamp - rtprio 95` in /etc/security/limits.conf, "
                       "LimitRTPRIO=95 in the systemd unit)");
    }
  }
  if (c.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<std::size_t>(c.cpu), &set);
    const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    if (e == 0) {
      status.affinity = true;
    } else {
      warn(status, "cannot pin the loop to CPU " + std::to_string(c.cpu) + ": " + err(e) +
                       "; check realtime.cpu against `nproc` and the cpuset of the service");
    }
  }
  if (prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0) {
    status.timer_slack = true;
  } else {
    warn(status, "PR_SET_TIMERSLACK 1 ns failed: " + err(errno) +
                     "; SCHED_OTHER wake-ups may be late by the default 50 us slack");
  }
  if (c.stack_prefault_kib > 0) {
    const std::size_t bytes = static_cast<std::size_t>(c.stack_prefault_kib) * 1024U;
    prefault_stack(bytes);
    status.stack_prefaulted_bytes = bytes;
  }
}

}  // namespace robodamp::rt
