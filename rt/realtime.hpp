// Start-up for real time. Process-wide: mlockall and /dev/cpu_dma_latency held at 0 while the object
// lives. Per thread (call on the loop thread before activation): SCHED_FIFO priority, CPU affinity,
// PR_SET_TIMERSLACK 1 ns and a stack prefault. Every step that is not permitted falls back and leaves one
// warning saying what the operator should change; nothing here is fatal.
#pragma once

#include <string>
#include <vector>

#include "rt_settings/rt_settings.hpp"

namespace robodamp::rt {

struct RealtimeStatus {
  bool memory_locked{false};
  bool dma_latency_held{false};
  bool fifo{false};
  int priority{0};
  bool affinity{false};
  bool timer_slack{false};
  std::size_t stack_prefaulted_bytes{0};
  std::vector<std::string> warnings;
};

class RealtimeProcess {
 public:
  RealtimeProcess(const RealtimeSettings& c, RealtimeStatus& status);
  ~RealtimeProcess();
  RealtimeProcess(const RealtimeProcess&) = delete;
  RealtimeProcess& operator=(const RealtimeProcess&) = delete;

 private:
  int dma_fd_{-1};
  bool locked_{false};
};

// On the calling thread.
void setup_realtime_thread(const RealtimeSettings& c, RealtimeStatus& status);

}  // namespace robodamp::rt
