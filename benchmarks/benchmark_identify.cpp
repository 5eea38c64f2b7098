// Modal identification of the robot SLE study's robot and workpiece (docs/performance.md: identification): the tool-workpiece
// FRF of config/milling/industrial_robot_aluminium.yaml in x (25 modes) and y (21 modes), 2-8000 Hz at
// 0.5 Hz with 0.5 % seeded complex noise, fitted in sub-bands (identify/modal_fit.hpp). One core.
// Counters: modes identified, and how many of the table's modes have one within 1 % in frequency.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>

#include "config/milling_config.hpp"
#include "identify/modal_fit.hpp"
#include "milling/structure.hpp"

namespace {

using namespace robodamp;

struct Case {
  identify::FrfData data;
  std::vector<double> truth_hz;
};

Case make_case(int axis) {
  const config::MillingConfig cfg =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/industrial_robot_aluminium.yaml");
  const config::StructureConfig& sc = *cfg.find_structure(cfg.structure);
  const milling::Structure s(sc, false);
  Case c;
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n(0.0, 0.005);
  for (double f = 2.0; f < 8000.0; f += 0.5) {
    const std::complex<double> h = s.frf(f)(axis, axis);
    c.data.f_hz.push_back(f), c.data.h.push_back(h * std::complex<double>(1.0 + n(rng), n(rng)));
  }
  for (const auto& part : sc.parts)
    for (const auto& m : part.modes[axis == 0 ? 0 : 3]) c.truth_hz.push_back(m.natural_freq_hz);
  return c;
}

int found(const identify::ModalFit& fit, const std::vector<double>& truth) {
  int n = 0;
  for (double t : truth) {
    bool hit = false;
    for (const auto& m : fit.modes) hit = hit || std::abs(m.natural_freq_hz - t) < 0.01 * t;
    n += hit ? 1 : 0;
  }
  return n;
}

void BM_IdentifyRobotSle(benchmark::State& state) {
  const Case x = make_case(0), y = make_case(1);
  identify::ModalFit fx, fy;
  for (auto _ : state) {
    fx = identify::fit_modes(x.data, {});
    fy = identify::fit_modes(y.data, {});
    benchmark::DoNotOptimize(fx.modes.data());
  }
  state.counters["modes_in_tables"] = static_cast<double>(x.truth_hz.size() + y.truth_hz.size());
  state.counters["modes_identified"] = static_cast<double>(fx.modes.size() + fy.modes.size());
  state.counters["within_1pct"] = found(fx, x.truth_hz) + found(fy, y.truth_hz);
  state.counters["fit_error_x_pct"] = fx.fit_error_pct;
  state.counters["fit_error_y_pct"] = fy.fit_error_pct;
}
BENCHMARK(BM_IdentifyRobotSle)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
