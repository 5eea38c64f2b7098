// SIGINT / SIGTERM become a flag the loop reads each tick (and trips on, through the safe state).
#pragma once

#include <atomic>

namespace robodamp::rt {

// The signal number last received (0 = none). Lock-free, async-signal-safe.
[[nodiscard]] std::atomic<int>& shutdown_signal();
// Installs the handlers for SIGINT and SIGTERM (idempotent).
void install_shutdown_handlers();

}  // namespace robodamp::rt
