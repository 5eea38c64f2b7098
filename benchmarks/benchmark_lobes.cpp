// Lobe diagram, direct test and SLE timing (README: milling analyses). The target: a 2000-speed
// lobe diagram of a 37-mode FRF in well under a second on one core.
#include <benchmark/benchmark.h>

#include <string>

#include "config/milling_config.hpp"
#include "milling/lobes.hpp"
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
    const auto d = m.diagram();                      // 2000 speeds
    grid = d.frequency_points;
    benchmark::DoNotOptimize(d.minimum.b_lim_m);
  }
  state.counters["modes"] = static_cast<double>(s.resonances().size());
  state.counters["chatter_freqs"] = static_cast<double>(grid);
  state.counters["speeds"] = lobes.points;
}
BENCHMARK(BM_LobeDiagram37Modes)->Unit(benchmark::kMillisecond);

void BM_DirectTestCriticalDepth(benchmark::State& state) {
  const milling::Structure s(robot_37_modes(), false);
  const milling::LobeModel m(s, milling::chatter_process(job().tool, job().material, job().cut), job().lobes);
  for (auto _ : state) benchmark::DoNotOptimize(m.critical_depth_m(10700.0));
}
BENCHMARK(BM_DirectTestCriticalDepth)->Unit(benchmark::kMillisecond);

void BM_SleOneSpeed(benchmark::State& state) {
  const milling::Structure s(*job().find_structure("robot_workpiece"), false);
  const auto cutter = milling::cutter_from(job().tool);
  const milling::CutConditions cut{job().cut.mode, job().cut.radial_mm, job().cut.axial_mm, job().cut.feed_per_tooth_mm};
  for (auto _ : state)
    benchmark::DoNotOptimize(milling::surface_location_error(s, cutter, job().material, cut, config::Axis::kX, 10700.0,
                                                             job().sle.axial_slices, job().sle.harmonics));
}
BENCHMARK(BM_SleOneSpeed)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
