// Independent tasks on a few threads, for the off-line runs that do not depend on each other (the bench's
// impact tests and gain-sweep runs). Each task writes only its own result, so the results, and anything
// assembled from them in task order afterwards, are the same byte for byte as a serial run. Off the
// real-time path.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace robodamp::analysis {

// The threads to use for `requested` (0: one per available core).
[[nodiscard]] std::size_t task_threads(std::size_t requested);

// Runs every task once on up to `threads` threads (the caller's included), taking them in order. Every
// thread is joined before it returns; if tasks threw, the first exception in task order is rethrown.
void run_tasks(const std::vector<std::function<void()>>& tasks, std::size_t threads);

}  // namespace robodamp::analysis

namespace robodamp::analysis {

// Asks the C library's allocator to keep the memory the process frees for its next allocations instead of
// handing it back to the kernel: blocks up to 64 MiB come from the heap (not a mapping of their own) and a
// heap's free top is kept up to 256 MiB. The accurate methods allocate and free matrices of 50 kB to 1 MB
// thousands of times per diagram on two threads; given back, each new one faulted its pages in again (17 600
// page faults and a third of a small diagram's time on the machine this was measured on; docs/performance.md).
// Call once at start, before the threads. Off the real-time path (the real-time process locks its memory).
void keep_freed_memory();

}  // namespace robodamp::analysis
