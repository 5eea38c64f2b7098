// Per-sample cost of the default chain (horizontal_c2: 6 sections) against a plain hand-written cascade
// with the same sections, and of the whole controller step. Closed-loop dependency throughout.
#include <benchmark/benchmark.h>

#include "kernels.hpp"

namespace {

using namespace robodamp;

template <class Kernel>
void run(benchmark::State& state, Kernel& kernel) {
  const auto u = bench::excitation();
  auto k = [&](double x) { return kernel(x); };
  for (auto _ : state) benchmark::DoNotOptimize(bench::run_closed_loop(k, u, 1000));
  state.SetItemsProcessed(state.iterations() * 1000);
}

void BM_PlainCascade(benchmark::State& state) {
  bench::PlainCascade c(bench::default_design().params.sections);
  auto k = [&](double x) { return c.process(x); };
  run(state, k);
}
BENCHMARK(BM_PlainCascade);

void BM_Chain(benchmark::State& state) {
  filters::BiquadCascade c(bench::default_design().params.sections);
  auto k = [&](double x) { return c.process(x); };
  run(state, k);
}
BENCHMARK(BM_Chain);

void BM_ControllerUpdate(benchmark::State& state) {
  control::Controller c(bench::default_design().params);
  auto k = [&](double x) { return c.update(x); };
  run(state, k);
}
BENCHMARK(BM_ControllerUpdate);

// Issue 17's comparison: the controller with 8 harmonic notches following the spindle (coefficients
// recomputed at 100 Hz) against a plain hand-written cascade of the same 14 sections; target <= 1.3x.
void BM_PlainCascadeWithNotches(benchmark::State& state) {
  bench::PlainCascade c(bench::notched_sections());
  auto k = [&](double x) { return c.process(x); };
  run(state, k);
}
BENCHMARK(BM_PlainCascadeWithNotches);

void BM_ControllerUpdateWithNotches(benchmark::State& state) {
  control::Controller c(bench::notched_params());
  (void)c.set_spindle_rpm(bench::kNotchedRpm);
  auto k = [&](double x) { return c.update(x); };
  run(state, k);
}
BENCHMARK(BM_ControllerUpdateWithNotches);

}  // namespace

BENCHMARK_MAIN();
