// The one way robodamp runs a background job off the real-time path (docs/architecture.md, "threads"): a
// std::jthread whose body gets the thread's stop_token, and a condition variable that wakes on notify(),
// on its timeout, or on a stop request, so no class keeps a stop flag, a notify and a join of its own.
// stop() (and the destructor) asks the body to stop and joins it, on every path, once; a body that waits
// through wait()/wait_for() returns from the wait at once. Used by the advisor, live stability, the CAN
// reconnect, the Modbus pollers and server, the DDS status thread, the dashboard's fleet, the telemetry
// drain and the emulated cell. Not for the real-time loop itself (runtime/cell.cpp starts that thread with
// its priority; it stops through the loop's own flag, checked every tick).
#pragma once

#include <pthread.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stop_token>
#include <string>
#include <thread>
#include <utility>

namespace robodamp::threads {

class Worker {
 public:
  Worker() = default;
  ~Worker() { stop(); }
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Runs body(stop_token) on a new thread named `name` (at most 15 characters: top, gdb and
  // /proc/<pid>/task/<tid>/comm show it). A worker already running is stopped first.
  template <class Body>
  void start(const std::string& name, Body body) {
    stop();
    thread_ = std::jthread([body = std::move(body)](std::stop_token stop) mutable { body(stop); });
    pthread_setname_np(thread_.native_handle(), name.substr(0, 15).c_str());
  }

  // Asks the body to stop (its waits return at once) and joins it. Idempotent; not from the body itself.
  void stop() {
    if (!thread_.joinable()) return;
    thread_.request_stop();
    thread_.join();
  }

  // Asks without waiting: an owner of several workers asks them all, then joins each (stop()), so that
  // none keeps working while another is joined.
  void request_stop() {
    if (thread_.joinable()) thread_.request_stop();
  }

  [[nodiscard]] bool running() const { return thread_.joinable(); }

  // Wakes the body's wait (after the caller changed what its predicate reads, under the same mutex).
  void notify() { cv_.notify_all(); }

  // For the body: waits on `lock` (the owner's mutex) until wake() holds or a stop is requested. True: there
  // is work (wake() holds) and no stop was asked; false: stop. A stop wins over work still queued (a sweep
  // of eighty speeds is not finished on the way out).
  template <class Lock, class Wake>
  bool wait(Lock& lock, std::stop_token stop, Wake wake) {
    return cv_.wait(lock, stop, std::move(wake)) && !stop.stop_requested();
  }

  // The same with a timeout: false on the timeout or a stop (check stop.stop_requested() to tell them apart).
  template <class Lock, class Rep, class Period, class Wake>
  bool wait_for(Lock& lock, std::stop_token stop, std::chrono::duration<Rep, Period> timeout, Wake wake) {
    return cv_.wait_for(lock, stop, timeout, std::move(wake)) && !stop.stop_requested();
  }

  // A pause of `period` that a stop request ends early; true when it was not stopped.
  template <class Rep, class Period>
  bool sleep_for(std::stop_token stop, std::chrono::duration<Rep, Period> period) {
    std::unique_lock<std::mutex> lock(sleep_m_);
    cv_.wait_for(lock, stop, period, [] { return false; });
    return !stop.stop_requested();
  }

 private:
  std::condition_variable_any cv_;
  std::mutex sleep_m_;
  std::jthread thread_;  // last: stopped and joined before the members the body uses are destroyed
};

}  // namespace robodamp::threads
