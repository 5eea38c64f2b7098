// What one robodamp tune evaluation costs (docs/performance.md: compensator synthesis): a candidate analysed against the
// discrete loop with its margins, damping window and command at the impact, with and without the damped
// lobes of a job; the impact's inverse-FFT prediction alone, and its set-up (the plant on the grid, once
// per plant).
#include <benchmark/benchmark.h>

#include <string>

#include "analysis/gain_path.hpp"
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

// A candidate as the search evaluates it: its loop on the plant the evaluator sampled once (the margins' and the
// quiet command's sweeps shared), the loop's constraints only and the whole evaluation without a job.
tune::Candidate near_preset() {
  tune::Candidate c;
  c.gain_ns_per_m = preset().controller.gain_ns_per_m, c.polarity = preset().controller.polarity;
  c.fz_hz = 20.0, c.zeta_z = 0.4, c.fp_hz = 14.0, c.zeta_p = 0.6, c.fa_hz = 8.0, c.fb_hz = 12.0;
  return c;
}

void BM_TuneCandidateConstraints(benchmark::State& state) {
  const tune::Evaluator evaluate(preset(), std::nullopt, {});
  for (auto _ : state) benchmark::DoNotOptimize(evaluate(near_preset(), true).k_max_ns_per_m);
}
BENCHMARK(BM_TuneCandidateConstraints)->Unit(benchmark::kMillisecond);

void BM_TuneCandidateWithoutJob(benchmark::State& state) {
  const tune::Evaluator evaluate(preset(), std::nullopt, {});
  for (auto _ : state) benchmark::DoNotOptimize(evaluate(near_preset()).peak_m_per_n);
}
BENCHMARK(BM_TuneCandidateWithoutJob)->Unit(benchmark::kMillisecond);

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

// The loop's largest stable gain (the log scan and its bisection), and one of its closed-loop spectral radii.
void BM_MaxStableGain(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  for (auto _ : state) benchmark::DoNotOptimize(analysis::max_stable_gain(m, preset().controller.polarity));
  state.counters["states"] = static_cast<double>(m.open_loop_unit().a.rows());
}
BENCHMARK(BM_MaxStableGain)->Unit(benchmark::kMillisecond);

// As the tune runs it: the margins' sweep, and the scan for K_max from its crossing gain.
void BM_MarginsThenMaxStableGain(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  const double k = preset().controller.gain_ns_per_m;
  const int pol = preset().controller.polarity;
  for (auto _ : state) {
    const analysis::Margins mg = analysis::margins(m, k, pol, std::nullopt);
    benchmark::DoNotOptimize(analysis::max_stable_gain(m, pol, mg.crossing_gain_ns_per_m));
  }
}
BENCHMARK(BM_MarginsThenMaxStableGain)->Unit(benchmark::kMillisecond);

void BM_Margins(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  for (auto _ : state)
    benchmark::DoNotOptimize(
        analysis::margins(m, preset().controller.gain_ns_per_m, preset().controller.polarity, std::nullopt));
}
BENCHMARK(BM_Margins)->Unit(benchmark::kMillisecond);

void BM_GainPathSpectralRadius(benchmark::State& state) {
  const analysis::LoopModel m(preset());
  const analysis::GainPath path(m.open_loop_unit());
  for (auto _ : state)
    benchmark::DoNotOptimize(path.spectral_radius(preset().controller.gain_ns_per_m, preset().controller.polarity));
}
BENCHMARK(BM_GainPathSpectralRadius)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
