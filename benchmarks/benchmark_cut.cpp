// Time-domain milling and semi-discretization, one core (docs/performance.md: milling in time): simulated seconds per
// wall second of one cut of the industrial-robot job (the robot SLE study's robot and workpiece, 3 teeth, 20 axial
// slices) and of the damped job (the real Controller and plant at 5 kHz); the time-domain critical depth
// at one speed; a 200-speed semi-discretization diagram of a single-mode structure.
#include <benchmark/benchmark.h>

#include <string>

#include "milling/cut_job.hpp"
#include "milling/lobes.hpp"
#include "milling/sdm.hpp"

namespace {

using namespace robodamp;

const std::string kJobs = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/";

struct Loaded {
  config::MillingConfig cfg;
  milling::Structure structure;
  milling::CutJob job;
};

Loaded load(const std::string& file) {
  config::MillingConfig cfg = config::load_milling_config(kJobs + file);
  milling::Structure structure(*cfg.find_structure(cfg.structure), false);
  return {cfg, structure, {}};
}

// Runs the job's cut once per iteration; x_real_time = simulated seconds per wall second.
void time_cuts(benchmark::State& state, const milling::CutJob& job) {
  double simulated = 0.0;
  for (auto _ : state) {
    const milling::CutOutcome o = milling::run_job(job);
    simulated += o.record.step_s * static_cast<double>(o.record.x_m.size());
    benchmark::DoNotOptimize(o.verdict.stable);
  }
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}

void BM_CutIndustrialRobot(benchmark::State& state) {
  Loaded l = load("industrial_robot_aluminium.yaml");
  const milling::CutJob job = milling::make_cut_job(l.cfg, l.structure, {});
  time_cuts(state, job);
  state.counters["modes"] = static_cast<double>(job.terms.size());
  state.counters["steps_per_tooth"] = job.settings.steps_per_tooth;
}
BENCHMARK(BM_CutIndustrialRobot)->Unit(benchmark::kMillisecond);

void BM_CutDamped(benchmark::State& state) {
  Loaded l = load("active_damping_c2.yaml");
  milling::CutOverrides o;
  o.rpm = 282.0, o.axial_mm = 0.6, o.damped = true;
  time_cuts(state, milling::make_cut_job(l.cfg, l.structure, o));
}
BENCHMARK(BM_CutDamped)->Unit(benchmark::kMillisecond);

void BM_CriticalDepthIndustrialRobot(benchmark::State& state) {
  Loaded l = load("industrial_robot_aluminium.yaml");
  const milling::CutJob job = milling::make_cut_job(l.cfg, l.structure, {});
  const milling::LobeModel lobes(l.structure, milling::chatter_process(l.cfg.tool, l.cfg.material, l.cfg.cut),
                                 l.cfg.lobes);
  const double guess = lobes.critical_depth_mm(job.settings.rpm);
  for (auto _ : state) {
    const milling::CriticalDepth c =
        milling::critical_depth(job.dynamics, job.cutter, job.material, job.settings, guess);
    benchmark::DoNotOptimize(c.depth_mm);
  }
}
BENCHMARK(BM_CriticalDepthIndustrialRobot)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_CriticalDepthDamped(benchmark::State& state) {
  Loaded l = load("active_damping_c2.yaml");
  milling::CutOverrides o;
  o.rpm = 282.0, o.damped = true;
  const milling::CutJob job = milling::make_cut_job(l.cfg, l.structure, o);
  for (auto _ : state) {
    const milling::CriticalDepth c =
        milling::critical_depth(job.dynamics, job.cutter, job.material, job.settings, 0.84);
    benchmark::DoNotOptimize(c.depth_mm);
  }
}
BENCHMARK(BM_CriticalDepthDamped)->Unit(benchmark::kMillisecond)->Iterations(2);

// A 600 Hz mode in x and y, 2 straight teeth, 5 % radial immersion, 40 steps per period, 200 speeds from
// 10 000 to 40 000 rpm, each by bisection to 1e-3 from the zero-order limit.
void BM_SdmDiagramSingleMode200Speeds(benchmark::State& state) {
  config::ModeConfig mode;
  mode.form = config::ModeForm::kStiffness;
  mode.natural_freq_hz = 600.0, mode.damping_ratio = 0.02, mode.stiffness_n_per_m = 5.6e6;
  const milling::Structure s({std::vector<config::ModeConfig>{mode}, {}, {}, std::vector<config::ModeConfig>{mode}});
  config::MaterialConfig mat;
  mat.kt_n_per_mm2 = 600.0, mat.kr_n_per_mm2 = 180.0;
  config::ToolConfig tool{config::ToolKind::kEndMill, 12.0, 2, 0.0};
  config::CutConfig cut;
  cut.radial_mm = 0.6;
  const milling::SdmModel sdm(milling::cutter_modal_terms(s, config::Axis::kX), milling::cutter_from(tool), mat,
                              cut.mode, cut.radial_mm, 1, 40);
  config::LobesConfig grid;
  grid.rpm_min = 10000, grid.rpm_max = 40000, grid.points = 200;
  const milling::LobeModel zoa(s, milling::chatter_process(tool, mat, cut), grid);
  const milling::LobeDiagram guesses = zoa.diagram();
  for (auto _ : state)
    for (const auto& p : guesses.curve) {
      const milling::SdmPoint q = sdm.critical(p.rpm, std::isfinite(p.b_lim_mm) ? p.b_lim_mm : 1.0);
      benchmark::DoNotOptimize(q.critical_depth_mm);
    }
}
BENCHMARK(BM_SdmDiagramSingleMode200Speeds)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
