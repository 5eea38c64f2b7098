// robodamp: active vibration damping for robotic milling. Each subcommand lives in
// apps/<name>_command.cpp with its options and handler; this only dispatches (apps/cli.hpp).
#include <cstdio>

#include <spdlog/spdlog.h>

#include "analysis/task_pool.hpp"
#include "apps/cli.hpp"

namespace {

// A build for x86-64-v3 (CMakeLists.txt, ROBODAMP_X86_64_V3) on a CPU without it would die on its first AVX2
// instruction: this check is compiled for every x86-64 and is the first thing main does.
#if defined(__x86_64__) && defined(__AVX2__)
__attribute__((target("arch=x86-64"))) bool cpu_lacks_x86_64_v3() {
  __builtin_cpu_init();
  return !__builtin_cpu_supports("x86-64-v3");
}
#else
bool cpu_lacks_x86_64_v3() { return false; }
#endif

}  // namespace

int main(int argc, char** argv) {
  if (cpu_lacks_x86_64_v3()) {
    std::fputs(
        "robodamp: this build needs an x86-64-v3 CPU (AVX2, FMA) and this one has not: build it here with "
        "cmake -DROBODAMP_X86_64_V3=OFF (README)\n",
        stderr);
    return 1;
  }
  // spdlog builds its logger registry on first use. Built here, before any thread exists, every thread that
  // logs later finds it made (the threads' start orders it): a first log from two threads at once would
  // build it under a guard that ThreadSanitizer cannot see in Debian's uninstrumented libspdlog.
  spdlog::default_logger_raw();
  robodamp::analysis::keep_freed_memory();
  return robodamp::apps::dispatch(argc, argv);
}
