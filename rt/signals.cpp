#include "rt/signals.hpp"

#include <csignal>

namespace robodamp::rt {

namespace {
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
extern "C" void on_shutdown_signal(int sig) { g_signal.store(sig, std::memory_order_relaxed); }
}  // namespace

std::atomic<int>& shutdown_signal() { return g_signal; }

void install_shutdown_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_shutdown_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace robodamp::rt
