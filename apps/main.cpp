// robodamp: active vibration damping for robotic milling. Each subcommand lives in
// apps/<name>_command.cpp with its options and handler; this only dispatches (apps/cli.hpp).
#include <spdlog/spdlog.h>

#include "analysis/task_pool.hpp"
#include "apps/cli.hpp"

int main(int argc, char** argv) {
  // spdlog builds its logger registry on first use. Built here, before any thread exists, every thread that
  // logs later finds it made (the threads' start orders it): a first log from two threads at once would
  // build it under a guard that ThreadSanitizer cannot see in Debian's uninstrumented libspdlog.
  spdlog::default_logger_raw();
  robodamp::analysis::keep_freed_memory();
  return robodamp::apps::dispatch(argc, argv);
}
