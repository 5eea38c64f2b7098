// callgrind_chain KERNEL N: runs KERNEL (plain | chain | controller | plain_notched | controller_notched) for N closed-loop samples inside
// run_kernel(), so `valgrind --tool=callgrind --toggle-collect=run_kernel` counts only that work.
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "kernels.hpp"

using namespace robodamp;

template <class Kernel>
__attribute__((noinline)) double run_kernel(Kernel& k, const std::array<double, 1024>& u, long n) {
  return bench::run_closed_loop(k, u, n);
}

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: callgrind_chain plain|chain|controller|plain_notched|controller_notched N\n");
    return 2;
  }
  const long n = std::atol(argv[2]);
  const auto d = bench::default_design();
  const auto u = bench::excitation();
  double y = 0.0;
  if (std::strcmp(argv[1], "plain") == 0) {
    bench::PlainCascade c(d.params.sections);
    auto k = [&](double x) { return c.process(x); };
    y = run_kernel(k, u, n);
  } else if (std::strcmp(argv[1], "chain") == 0) {
    filters::BiquadCascade c(d.params.sections);
    auto k = [&](double x) { return c.process(x); };
    y = run_kernel(k, u, n);
  } else if (std::strcmp(argv[1], "controller") == 0) {
    control::Controller c(d.params);
    auto k = [&](double x) { return c.update(x); };
    y = run_kernel(k, u, n);
  } else if (std::strcmp(argv[1], "plain_notched") == 0) {
    bench::PlainCascade c(bench::notched_sections());
    auto k = [&](double x) { return c.process(x); };
    y = run_kernel(k, u, n);
  } else if (std::strcmp(argv[1], "controller_notched") == 0) {
    control::Controller c(bench::notched_params());
    (void)c.set_spindle_rpm(bench::kNotchedRpm);
    auto k = [&](double x) { return c.update(x); };
    y = run_kernel(k, u, n);
  } else {
    std::fprintf(stderr, "unknown kernel %s\n", argv[1]);
    return 2;
  }
  std::printf("%s %ld samples, last output %.6g, %zu sections\n", argv[1], n, y, d.params.sections.count);
  return 0;
}
