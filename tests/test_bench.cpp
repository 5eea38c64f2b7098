// The bench run against the analysis: open-loop FRFs from simulated impacts against the modal model,
// the measured improvement against the prediction for every preset, the gain sweep across K_max,
// saturation, and the frequency-resolution effect.
#include <gtest/gtest.h>

#include <cmath>

#include <algorithm>
#include <atomic>
#include <complex>
#include <iostream>
#include <string>
#include <stdexcept>
#include <thread>

#include "analysis/bench_run.hpp"
#include "analysis/task_pool.hpp"
#include "test_util.hpp"

namespace {

using namespace robodamp;

config::Config quiet(config::Config c) {
  c.sensor.noise_density_ug_per_rthz = 0.0;
  c.sensor.adc_bits = 32;  // undithered 24-bit quantisation of a small response is not "no noise"
  c.disturbances.drives_on = false;
  return c;
}

void expect_open_loop_matches(const analysis::Bench& bench, double tol_db, double min_coherence) {
  const auto& m = bench.model();
  const auto& cfg = m.config();
  const auto r = analysis::improvements(m, 0.0, 1, true);
  for (std::size_t loc = 0; loc < m.plant().locations.size(); ++loc) {
    const auto t = bench.impact_test({loc, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, false, 0.0, 1});
    for (const auto& f : r) {
      if (f.excitation != loc) continue;
      const auto p =
          analysis::measured_peak(t.receptance[f.response], cfg.analysis.band_min_hz, cfg.analysis.band_max_hz);
      EXPECT_NEAR(20 * std::log10(p.magnitude_m_per_n / f.open_peak_m_per_n), 0.0, tol_db) << f.name;
      EXPECT_NEAR(p.freq_hz, f.open_peak_freq_hz, 0.02) << f.name;
      EXPECT_GT(p.coherence_min, min_coherence) << f.name;
    }
  }
}

TEST(Bench, OpenLoopImpactsMatchTheModalModelWithoutNoise) {
  const analysis::Bench bench(quiet(config::load_config_file(test::preset("horizontal_c2"))));
  expect_open_loop_matches(bench, 0.5, 0.99);
}

// The impact campaign's H1, with its accelerometers' AC coupling and the records' timing worked out
// (analysis/bench_run.cpp, receptance()), is the structure's receptance itself, not near its peaks only:
// noise-free, every path of robot A and of the default preset (whose Table 1 residues have real parts: an
// improper accelerance, whose impulse no sample holds) within 0.05 % of its peak and 0.05 deg from 2 to
// 60 Hz (0.01 % and 0.03 deg here; with the coupling and the timing left in robot A is 2.8 deg off at 3.4 Hz,
// with the impulse left out the preset is 12 deg off at 60 Hz).
TEST(Bench, TheImpactCampaignsFrfIsTheStructuresReceptance) {
  for (const std::string& file : {std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/robot_a_two_modes.yaml",
                                  test::preset("horizontal_c2")}) {
    const analysis::Bench bench(quiet(config::load_config_file(file)));
    const auto& m = bench.model();
    const auto& cfg = m.config();
    for (std::size_t exc = 0; exc < m.plant().locations.size(); ++exc) {
      const auto t = bench.impact_test({exc, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, false, 0.0, 1});
      for (std::size_t resp = 0; resp < t.receptance.size(); ++resp) {
        if (m.plant().path(resp, exc) == nullptr) continue;
        const analysis::FrfEstimate& e = t.receptance[resp];
        // Errors against the path's peak (an antiresonance's relative error is no measure of the chain), the
        // phase where the path is within 20 dB of its peak.
        double peak = 0.0;
        for (std::size_t k = 0; k < e.f_hz.size(); ++k)
          if (e.f_hz[k] >= 2.0 && e.f_hz[k] <= 60.0)
            peak = std::max(peak, std::abs(m.plant().receptance(resp, exc, e.f_hz[k])));
        int checked = 0;
        double err = 0.0, deg_err = 0.0, err_at = 0.0, deg_at = 0.0;
        for (std::size_t k = 0; k < e.f_hz.size(); ++k) {
          if (e.f_hz[k] < 2.0 || e.f_hz[k] > 60.0) continue;
          const std::complex<double> want = m.plant().receptance(resp, exc, e.f_hz[k]);
          const double de = std::abs(e.h1[k] - want) / peak;
          if (de > err) err = de, err_at = e.f_hz[k];
          if (std::abs(want) > 0.1 * peak) {
            const double dp = std::abs(std::arg(e.h1[k] / want) * 180.0 / M_PI);
            if (dp > deg_err) deg_err = dp, deg_at = e.f_hz[k];
          }
          ++checked;
        }
        const std::string where = file + " H" + std::to_string(resp + 1) + std::to_string(exc + 1);
        EXPECT_LT(err, 5e-4) << where << " at " << err_at << " Hz";
        EXPECT_LT(deg_err, 0.05) << where << " at " << deg_at << " Hz";
        std::cout << where << ": " << 100.0 * err << " % of the peak at " << err_at << " Hz, " << deg_err << " deg at "
                  << deg_at << " Hz\n";
        EXPECT_GT(checked, 100) << file;
      }
    }
  }
}

TEST(Bench, OpenLoopImpactsMatchTheModalModelWithNoiseAndDrives) {
  // Stated in docs/commands.md: 1000 N impacts, 10 averages of 10 s records, noise 3 ug/sqrt(Hz), 3 Hz drives on.
  const analysis::Bench bench(config::load_config_file(test::preset("horizontal_c2")));
  expect_open_loop_matches(bench, 0.1, 0.99);
}

TEST(Bench, MeasuredImprovementMatchesTheAnalysisForEveryPreset) {
  for (const char* name : {"horizontal_c2", "horizontal_c1", "horizontal_c3", "vertical_c1"}) {
    const analysis::Bench bench(config::load_config_file(test::preset(name)));
    const auto& cfg = bench.model().config();
    const auto predicted =
        analysis::improvements(bench.model(), cfg.controller.gain_ns_per_m, cfg.controller.polarity, true);
    for (std::size_t loc = 0; loc < 2; ++loc) {
      const auto off = bench.impact_test({loc, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, false, 0.0, 1});
      const auto on = bench.impact_test({loc, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, true,
                                         cfg.controller.gain_ns_per_m, cfg.controller.polarity});
      EXPECT_EQ(on.saturation_time_s, 0.0) << name;
      for (const auto& f : predicted) {
        if (f.excitation != loc) continue;
        const double lo = cfg.analysis.band_min_hz, hi = cfg.analysis.band_max_hz;
        const double measured = (analysis::measured_peak(off.receptance[f.response], lo, hi).magnitude_m_per_n /
                                     analysis::measured_peak(on.receptance[f.response], lo, hi).magnitude_m_per_n -
                                 1.0) *
                                100.0;
        EXPECT_NEAR(measured, f.improvement_pct, 0.05 * std::abs(f.improvement_pct)) << name << " " << f.name;
      }
    }
  }
}

TEST(Bench, TimeDomainDivergesAboveThePredictedGainLimitAndNotBelow) {
  const analysis::Bench bench(config::load_config_file(test::preset("horizontal_c2")));
  const auto k_max = analysis::max_stable_gain(bench.model(), 1);
  ASSERT_TRUE(k_max);
  const auto below = bench.divergence_run(0.9 * *k_max, 1);
  const auto above = bench.divergence_run(1.1 * *k_max, 1);
  EXPECT_FALSE(below.predicted_unstable);
  EXPECT_FALSE(below.diverged);
  EXPECT_TRUE(above.predicted_unstable);
  EXPECT_TRUE(above.diverged);
  // The measured growth rate is the predicted closed-loop pole's.
  EXPECT_NEAR(below.measured_growth_per_s, below.predicted_growth_per_s, 0.1 * std::abs(below.predicted_growth_per_s));
  EXPECT_NEAR(above.measured_growth_per_s, above.predicted_growth_per_s, 0.1 * std::abs(above.predicted_growth_per_s));
}

TEST(Bench, SaturationLowersTheImprovement) {
  const analysis::Bench bench(config::load_config_file(test::preset("horizontal_c2")));
  const auto& cfg = bench.model().config();
  const std::size_t aml = bench.model().actuator_location();
  const auto off = bench.impact_test({aml, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, false, 0.0, 1});
  const auto sat = bench.impact_test({aml, cfg.bench.saturating_impact_peak_n, cfg.bench.saturating_impact_duration_ms,
                                      true, cfg.controller.gain_ns_per_m, 1});
  const auto predicted = analysis::improvements(bench.model(), cfg.controller.gain_ns_per_m, 1, true);
  const double lo = cfg.analysis.band_min_hz, hi = cfg.analysis.band_max_hz;
  const double measured = (analysis::measured_peak(off.receptance[aml], lo, hi).magnitude_m_per_n /
                               analysis::measured_peak(sat.receptance[aml], lo, hi).magnitude_m_per_n -
                           1.0) *
                          100.0;
  EXPECT_GT(sat.saturation_time_s, 0.1);
  EXPECT_LT(measured, 0.9 * predicted[2].improvement_pct);
  EXPECT_GT(measured, 0.0);  // clipped damping is still damping
}

TEST(Bench, CoarseResolutionUnderReadsTheOpenLoopPeak) {
  config::Config cfg = quiet(config::load_config_file(test::preset("horizontal_c2")));
  cfg.bench.zero_pad = 1;
  cfg.bench.record_s = 2.0;  // 0.5 Hz bins against a 0.44 Hz half-power bandwidth at 9.2 Hz
  cfg.bench.averages = 2;
  const analysis::Bench bench(cfg);
  const auto t = bench.impact_test({1, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms, false, 0.0, 1});
  const auto p = analysis::measured_peak(t.receptance[1], cfg.analysis.band_min_hz, cfg.analysis.band_max_hz);
  const double model_peak = analysis::improvements(bench.model(), 0.0, 1, true)[2].open_peak_m_per_n;
  EXPECT_LT(p.magnitude_m_per_n, 0.97 * model_peak);
}

TEST(TaskPool, RunsEveryTaskOnceOnEveryThreadCountAndRethrowsTheFirstError) {
  for (std::size_t threads : {1u, 2u, 3u, 64u}) {
    std::vector<std::atomic<int>> runs(40);
    std::vector<std::function<void()>> tasks;
    for (std::size_t i = 0; i < runs.size(); ++i) tasks.emplace_back([&runs, i] { ++runs[i]; });
    analysis::run_tasks(tasks, threads);
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1) << threads << " threads";
    // Tasks 7 and 3 throw: every task still runs, every thread is joined, and task 3's error comes out.
    std::atomic<int> ran{0};
    std::vector<std::function<void()>> failing;
    for (int i = 0; i < 10; ++i)
      failing.emplace_back([&ran, i] {
        ++ran;
        if (i == 3 || i == 7) throw std::runtime_error("task " + std::to_string(i));
      });
    try {
      analysis::run_tasks(failing, threads);
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "task 3");
    }
    EXPECT_EQ(ran.load(), 10);
  }
  analysis::run_tasks({}, 4);  // nothing to do
  EXPECT_EQ(analysis::task_threads(3), 3u);
  EXPECT_GE(analysis::task_threads(0), 1u);
}

}  // namespace
