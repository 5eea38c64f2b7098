// What one robodamp tune evaluation costs (docs/performance.md: compensator synthesis): a candidate analysed against the
// discrete loop with its margins, damping window and command at the impact, with and without the damped
// lobes of a job; the impact's inverse-FFT prediction alone, and its set-up (the plant on the grid, once
// per plant).
#include <benchmark/benchmark.h>

#include <string>

#include "analysis/impact_command.hpp"
#include "analysis/loop_model.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/compensator_search.hpp"

namespace {

using namespace robodamp;

const std::string kDir = ROBODAMP_SOURCE_DIR;

const config::Config& preset() {
  static const config::Config c = config::load_config_file(kDir + "/config/presets/tuned_horizontal.yaml");
  return c;
}

void BM_TuneEvaluationWithJob(benchmark::State& state) {
  const tune::Evaluator evaluate(preset(), config::load_milling_config(kDir + "/config/milling/active_damping_c2.yaml"),
                                 {});
  for (auto _ : state) benchmark::DoNotOptimize(evaluate.assess(preset()).min_depth_mm);
}
BENCHMARK(BM_TuneEvaluationWithJob)->Unit(benchmark::kMillisecond);

void BM_TuneEvaluationWithoutJob(benchmark::State& state) {
  const tune::Evaluator evaluate(preset(), std::nullopt, {});
  for (auto _ : state) benchmark::DoNotOptimize(evaluate.assess(preset()).peak_m_per_n);
}
BENCHMARK(BM_TuneEvaluationWithoutJob)->Unit(benchmark::kMillisecond);

void BM_ImpactCommandPeak(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  analysis::ImpactCommand predict(m, 1000.0, 1e-3);
  for (auto _ : state)
    benchmark::DoNotOptimize(predict.peak(m, preset().controller.gain_ns_per_m, preset().controller.polarity));
}
BENCHMARK(BM_ImpactCommandPeak)->Unit(benchmark::kMillisecond);

void BM_ImpactCommandSetUp(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  for (auto _ : state) {
    analysis::ImpactCommand predict(m, 1000.0, 1e-3);
    benchmark::DoNotOptimize(&predict);
  }
}
BENCHMARK(BM_ImpactCommandSetUp)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
