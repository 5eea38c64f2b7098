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
