// Simulated seconds per wall second of the bench's closed loop on the default preset: the simulated
// plant (exact ZOH in modal block form, delayed actuator, control accelerometer with noise, the 3 Hz drive
// vibration) and the real-time Controller, one loop tick per iteration, one core; at oversampling 1 (the
// preset) and 4. Beside it, the plant alone (a fixed command sequence instead of the controller), with and
// without the sensor's noise generator, to show where a tick's time goes (docs/performance.md: plant speed).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "analysis/loop_model.hpp"
#include "analysis/pose_schedule.hpp"
#include "control/controller.hpp"
#include "sim_plant/plant.hpp"

namespace {

using namespace robodamp;

config::Config preset(int oversampling) {
  config::Config c = config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/horizontal_c2.yaml");
  c.plant.oversampling = oversampling;
  return c;
}

void set_counters(benchmark::State& state, const config::Config& cfg, const sim::Plant& plant, int ticks) {
  state.SetItemsProcessed(state.iterations() * ticks);
  // Simulated seconds per wall second = ticks per second / loop rate.
  state.counters["x_real_time"] = benchmark::Counter(static_cast<double>(state.iterations()) * ticks / cfg.loop.rate_hz,
                                                     benchmark::Counter::kIsRate);
  state.counters["states"] = static_cast<double>(plant.state_count());
}

// The plant alone: sense and step with a command that does not depend on the reading.
void plant_alone(benchmark::State& state, config::Config cfg) {
  const analysis::LoopModel model(cfg);
  sim::Plant plant(model.plant(), cfg);
  plant.add_excitation(sim::make_drive_vibration(model.plant(), cfg));
  const int ticks = 5000;
  double sum = 0.0;
  for (auto _ : state) {
    for (int k = 0; k < ticks; ++k) {
      sum += plant.sense().accel_mps2;
      plant.step(0.5 * static_cast<double>((k >> 6) & 1));
    }
    benchmark::DoNotOptimize(sum);
  }
  set_counters(state, cfg, plant, ticks);
}

void BM_PlantAlone(benchmark::State& state) { plant_alone(state, preset(static_cast<int>(state.range(0)))); }
BENCHMARK(BM_PlantAlone)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_PlantAloneNoiseless(benchmark::State& state) {
  config::Config cfg = preset(static_cast<int>(state.range(0)));
  cfg.sensor.noise_density_ug_per_rthz = 0.0;
  plant_alone(state, cfg);
}
BENCHMARK(BM_PlantAloneNoiseless)->Arg(1)->Unit(benchmark::kMillisecond);

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
  set_counters(state, cfg, plant, ticks);
}
BENCHMARK(BM_PlantAndController)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond);

// The HIL emulator along a pose trajectory (docs/pose_dynamics.md): each pose update builds the robot
// model's modes at the pose and retunes the plant (a new exact discretisation, the state carried over).
// At its default period (0.02 s) this costs one update per 100 loop ticks.
void BM_PoseRetune(benchmark::State& state) {
  const config::Config cfg =
      config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/pose_scheduled_c2.yaml");
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  const auto at = [&](double q2) {
    return sim::build_plant_model(analysis::config_at_pose(cfg, analysis::pose_modes(model, {-100.0, q2, 90.0}, 0, 3)));
  };
  sim::Plant plant(at(10.0), cfg);
  double q2 = 10.0;
  for (auto _ : state) {
    q2 = q2 < 130.0 ? q2 + 0.1 : 10.0;
    plant.retune(at(q2));
    plant.step(0.0);
  }
}
BENCHMARK(BM_PoseRetune)->Unit(benchmark::kMicrosecond);

// The same with the structures built beforehand (what the emulator does: the trajectory is known before
// the run): the retune alone.
void BM_PoseRetunePrebuilt(benchmark::State& state) {
  const config::Config cfg =
      config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/pose_scheduled_c2.yaml");
  const config::RobotModelConfig model = config::load_robot_model(cfg.pose_schedule->model_resolved);
  std::vector<sim::PlantModel> models;
  for (double q2 = 10.0; q2 < 130.0; q2 += 1.0)
    models.push_back(
        sim::build_plant_model(analysis::config_at_pose(cfg, analysis::pose_modes(model, {-100.0, q2, 90.0}, 0, 3))));
  sim::Plant plant(models.front(), cfg);
  std::size_t i = 0;
  for (auto _ : state) {
    plant.retune(models[i]);
    i = (i + 1) % models.size();
    plant.step(0.0);
  }
}
BENCHMARK(BM_PoseRetunePrebuilt)->Unit(benchmark::kMicrosecond);

// The configuration-time analysis of the preset's schedule: two regions, 27 poses each (robodamp analyze,
// and every cell's configure()).
void BM_PoseScheduleAnalysis(benchmark::State& state) {
  const config::Config cfg =
      config::load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/presets/pose_scheduled_c2.yaml");
  for (auto _ : state) benchmark::DoNotOptimize(analysis::analyse_pose_schedule(cfg));
}
BENCHMARK(BM_PoseScheduleAnalysis)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
