// Lobe diagram, direct test and SLE timing (docs/performance.md: milling analyses). The target: a 2000-speed
// lobe diagram of a 37-mode FRF in well under a second on one core.
#include <benchmark/benchmark.h>

#include <string>

#include "config/milling_config.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/sdm.hpp"
#include "milling/structure.hpp"
#include "milling/tool_dynamics.hpp"
#include "milling/sle.hpp"

namespace {

using namespace robodamp;

const config::MillingConfig& job() {
  static const config::MillingConfig j =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/industrial_robot_aluminium.yaml");
  return j;
}

// The robot alone: 20 x modes + 17 y modes = 37.
config::StructureConfig robot_37_modes() {
  config::StructureConfig s = *job().find_structure("robot_workpiece");
  s.parts.resize(1);
  return s;
}

void BM_LobeDiagram37Modes(benchmark::State& state) {
  const milling::Structure s(robot_37_modes(), false);
  auto lobes = job().lobes;
  lobes.points = 2000;
  const auto process = milling::chatter_process(job().tool, job().material, job().cut);
  std::size_t grid = 0;
  for (auto _ : state) {
    const milling::LobeModel m(s, process, lobes);  // frequency grid, eigenvalues, branch tracking
    const auto d = m.diagram();                     // 2000 speeds
    grid = d.frequency_points;
    benchmark::DoNotOptimize(d.minimum.b_lim_mm);
  }
  state.counters["modes"] = static_cast<double>(s.resonances().size());
  state.counters["chatter_freqs"] = static_cast<double>(grid);
  state.counters["speeds"] = lobes.points;
}
BENCHMARK(BM_LobeDiagram37Modes)->Unit(benchmark::kMillisecond);

void BM_DirectTestCriticalDepth(benchmark::State& state) {
  const milling::Structure s(robot_37_modes(), false);
  const milling::LobeModel m(s, milling::chatter_process(job().tool, job().material, job().cut), job().lobes);
  for (auto _ : state) benchmark::DoNotOptimize(m.critical_depth_mm(10700.0));
}
BENCHMARK(BM_DirectTestCriticalDepth)->Unit(benchmark::kMillisecond);

// The open-loop semi-discretization of the whole 46-mode industrial robot (robot and workpiece), issue 57:
// one monodromy matrix (40 intervals, 172 states) and one speed's critical depth from a first guess of 3 mm.
void BM_OpenSdm46ModesMultiplier(benchmark::State& state) {
  const milling::Structure s(job().selected_structure(), false);
  const milling::SdmModel sdm(milling::cutter_modal_terms(s, job().cut.feed_axis), milling::cutter_from(job().tool),
                              job().material, job().cut.mode, job().cut.radial_mm, job().time_domain.axial_slices,
                              job().time_domain.sdm_steps_per_period);
  const double rpm = static_cast<double>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(sdm.multiplier(3.0, rpm));
}
BENCHMARK(BM_OpenSdm46ModesMultiplier)->Arg(500)->Arg(1156)->Arg(2500)->Arg(10700)->Unit(benchmark::kMillisecond);

void BM_OpenSdm46ModesCriticalDepth(benchmark::State& state) {
  const milling::Structure s(job().selected_structure(), false);
  const milling::AccurateStability truth(s, job());
  for (auto _ : state) benchmark::DoNotOptimize(truth.critical(static_cast<double>(state.range(0)), 3.0));
}
BENCHMARK(BM_OpenSdm46ModesCriticalDepth)->Arg(1156)->Arg(10700)->Unit(benchmark::kMillisecond);

// The accurate damped lobes (issue 27): the sampled loop's semi-discretization of active_damping_c2.yaml with
// C2 closed, over the job's 200 SDM speeds, each from the zero-order limit; threads: the speeds' task pool.
void BM_DampedSdmLobes(benchmark::State& state) {
  const config::MillingConfig j =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml");
  const milling::Structure damped(j.structures.front(), true);
  config::LobesConfig grid = j.lobes;
  grid.points = j.time_domain.sdm_points;
  const milling::LobeDiagram guess =
      milling::LobeModel(damped, milling::chatter_process(j.tool, j.material, j.cut), grid).diagram();
  std::vector<double> rpm, mm;
  for (const auto& p : guess.curve) rpm.push_back(p.rpm), mm.push_back(p.b_lim_mm);
  const milling::AccurateStability truth(damped, j);
  for (auto _ : state) benchmark::DoNotOptimize(truth.critical(rpm, mm, static_cast<std::size_t>(state.range(0))));
  state.counters["speeds"] = static_cast<double>(rpm.size());
}
BENCHMARK(BM_DampedSdmLobes)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

// One speed's damped critical depth (700 rpm, 143 loop periods per tooth period).
void BM_DampedSdmCriticalDepth(benchmark::State& state) {
  const config::MillingConfig j =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml");
  const milling::Structure damped(j.structures.front(), true);
  const milling::AccurateStability truth(damped, j);
  for (auto _ : state) benchmark::DoNotOptimize(truth.critical(700.0, 1.071));
}
BENCHMARK(BM_DampedSdmCriticalDepth)->Unit(benchmark::kMillisecond);

void BM_SleOneSpeed(benchmark::State& state) {
  const milling::Structure s(*job().find_structure("robot_workpiece"), false);
  const auto cutter = milling::cutter_from(job().tool);
  const milling::CutConditions cut{job().cut.mode, job().cut.radial_mm, job().cut.axial_mm,
                                   job().cut.feed_per_tooth_mm};
  for (auto _ : state)
    benchmark::DoNotOptimize(milling::surface_location_error(s, cutter, job().material, cut, config::Axis::kX, 10700.0,
                                                             job().sle.axial_slices, job().sle.harmonics));
}
BENCHMARK(BM_SleOneSpeed)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
