// What each part of the main job (`robodamp bench` on the default preset) costs, one core each: loading
// the configuration and building the loop model, the closed-loop analysis, one impact test's simulation
// (10 hits, ~110 s simulated, control on) and its H1 estimate (the FFTs), one gain-sweep run (20 s), and
// the whole bench run, serial and on two threads. docs/performance.md: "Main job: what each part costs".
#include <benchmark/benchmark.h>

#include <string>

#include "analysis/bench_run.hpp"
#include "analysis/loop_model.hpp"
#include "analysis/spectral.hpp"

namespace {

using namespace robodamp;

const std::string kPreset = std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/horizontal_c2.yaml";

void BM_LoadAndModel(benchmark::State& state) {
  for (auto _ : state) {
    const analysis::Bench bench(config::load_config_file(kPreset));
    benchmark::DoNotOptimize(&bench);
  }
}
BENCHMARK(BM_LoadAndModel)->Unit(benchmark::kMillisecond);

void BM_Analysis(benchmark::State& state) {
  const config::Config cfg = config::load_config_file(kPreset);
  const analysis::LoopModel model(cfg);
  for (auto _ : state) {
    const analysis::AnalysisResult r = analysis::analyse(model, cfg.controller.gain_ns_per_m, cfg.controller.polarity);
    benchmark::DoNotOptimize(r.spectral_radius);
  }
}
BENCHMARK(BM_Analysis)->Unit(benchmark::kMillisecond);

// One impact test end to end (simulation and H1 estimate), control on at the TCP.
void BM_ImpactTest(benchmark::State& state) {
  const config::Config cfg = config::load_config_file(kPreset);
  const analysis::Bench bench(cfg);
  const analysis::ImpactTest t{0,    cfg.bench.impact_peak_n,      cfg.bench.impact_duration_ms,
                               true, cfg.controller.gain_ns_per_m, cfg.controller.polarity};
  double simulated_s = 0.0;
  for (auto _ : state) {
    const analysis::ImpactTestResult r = bench.impact_test(t);
    simulated_s += r.simulated_s;
    benchmark::DoNotOptimize(r.peak_actuator_force_n);
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ImpactTest)->Unit(benchmark::kMillisecond);

// The H1 estimate of one impact test alone: 10 records of 10 s at 5 kHz, force and two responses,
// rectangular window, zero-padded x8, bins to 1.5 x the analysis band.
void BM_ImpactFrf(benchmark::State& state) {
  const config::Config cfg = config::load_config_file(kPreset);
  const auto n = static_cast<std::size_t>(cfg.bench.record_s * cfg.loop.rate_hz);
  std::vector<double> force(n, 0.0);
  std::vector<std::vector<double>> responses(2, std::vector<double>(n, 0.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / cfg.loop.rate_hz;
    force[i] = i >= 250 && i < 255 ? 1000.0 : 0.0;
    responses[0][i] = std::exp(-1.2 * t) * std::sin(57.8 * t);
    responses[1][i] = std::exp(-1.4 * t) * std::sin(132.0 * t);
  }
  for (auto _ : state) {
    analysis::FrfAccumulator acc(n, cfg.loop.rate_hz, cfg.bench.zero_pad, analysis::Window::kRectangular,
                                 cfg.analysis.band_max_hz * 1.5, responses.size());
    for (int r = 0; r < cfg.bench.averages; ++r) acc.add(force, responses);
    const analysis::FrfEstimate e = acc.result(1);
    benchmark::DoNotOptimize(e.h1.data());
  }
  state.counters["transforms"] = static_cast<double>(cfg.bench.averages * 3);
}
BENCHMARK(BM_ImpactFrf)->Unit(benchmark::kMillisecond);

void BM_DivergenceRun(benchmark::State& state) {
  const config::Config cfg = config::load_config_file(kPreset);
  const analysis::Bench bench(cfg);
  for (auto _ : state) {
    const analysis::DivergenceRun d = bench.divergence_run(1.1 * 4804.8, cfg.controller.polarity);
    benchmark::DoNotOptimize(d.growth_ratio);
  }
  state.counters["x_real_time"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * cfg.bench.sweep_duration_s, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DivergenceRun)->Unit(benchmark::kMillisecond);

// The whole bench run (what `robodamp bench` computes; without printing, JSON and plots), on 1 thread
// (serial) and on 2 (this machine's cores). Real time, since the work is on several threads.
void BM_BenchRun(benchmark::State& state) {
  const analysis::Bench bench(config::load_config_file(kPreset));
  for (auto _ : state) {
    const analysis::BenchReport r = bench.run({}, static_cast<std::size_t>(state.range(0)));
    benchmark::DoNotOptimize(r.simulated_s);
  }
}
BENCHMARK(BM_BenchRun)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
