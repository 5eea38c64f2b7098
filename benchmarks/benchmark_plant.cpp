// Simulated seconds per wall second of the bench's closed loop on the default preset: the simulated
// plant (exact ZOH, 4x oversampling, delayed actuator, control accelerometer with noise, the 3 Hz drive
// vibration) and the real-time Controller, one loop tick per iteration, one core.
#include <benchmark/benchmark.h>

#include <string>

#include "analysis/loop_model.hpp"
#include "control/controller.hpp"
#include "sim_plant/plant.hpp"

namespace {

using namespace robodamp;

config::Config preset(int oversampling) {
  config::Config c =
      config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/horizontal_c2.yaml");
  c.plant.oversampling = oversampling;
  return c;
}

void BM_PlantAndController(benchmark::State& state) {
  const config::Config cfg = preset(static_cast<int>(state.range(0)));
  const analysis::LoopModel model(cfg);
  sim::Plant plant(model.plant(), cfg);
  plant.add_excitation(sim::make_drive_vibration(model.plant(), cfg));
  control::Controller controller(model.chain().params);
  double command = 0.0;
  const int ticks = 5000;  // one simulated second at 5 kHz
  for (auto _ : state) {
    for (int k = 0; k < ticks; ++k) {
      const double next = controller.update(plant.sense().accel_mps2);
      plant.step(command);
      command = next;
    }
    benchmark::DoNotOptimize(command);
  }
  state.SetItemsProcessed(state.iterations() * ticks);
  // Simulated seconds per wall second = ticks per second / loop rate.
  state.counters["x_real_time"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * ticks / cfg.loop.rate_hz, benchmark::Counter::kIsRate);
  state.counters["states"] = static_cast<double>(plant.state_count());
}
BENCHMARK(BM_PlantAndController)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
