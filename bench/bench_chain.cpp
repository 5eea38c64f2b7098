// Per-sample cost of the default chain (horizontal_c2: 6 sections) against a plain hand-written cascade
// with the same sections, and of the whole controller step. Closed-loop dependency throughout.
#include <benchmark/benchmark.h>

#include "kernels.hpp"

namespace {

using namespace robodamp;

void BM_PlainCascade(benchmark::State& state) {
  const auto d = bench::default_design();
  bench::PlainCascade c(d.params.sections);
  const auto u = bench::excitation();
  auto k = [&](double x) { return c.process(x); };
  for (auto _ : state) benchmark::DoNotOptimize(bench::run_closed_loop(k, u, 1000));
  state.SetItemsProcessed(state.iterations() * 1000);
}
BENCHMARK(BM_PlainCascade);

void BM_Chain(benchmark::State& state) {
  const auto d = bench::default_design();
  filters::BiquadCascade c(d.params.sections);
  const auto u = bench::excitation();
  auto k = [&](double x) { return c.process(x); };
  for (auto _ : state) benchmark::DoNotOptimize(bench::run_closed_loop(k, u, 1000));
  state.SetItemsProcessed(state.iterations() * 1000);
}
BENCHMARK(BM_Chain);

void BM_ControllerUpdate(benchmark::State& state) {
  const auto d = bench::default_design();
  control::Controller c(d.params);
  const auto u = bench::excitation();
  auto k = [&](double x) { return c.update(x); };
  for (auto _ : state) benchmark::DoNotOptimize(bench::run_closed_loop(k, u, 1000));
  state.SetItemsProcessed(state.iterations() * 1000);
}
BENCHMARK(BM_ControllerUpdate);

}  // namespace

BENCHMARK_MAIN();
