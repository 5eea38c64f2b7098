// Compensator synthesis (robodamp tune, docs/tuning.md): the rational block's shape, the evaluation against
// the analysis and the damped lobes (C1 and C2 as the issue quotes them), a short seeded search repeating
// exactly and beating the open loop within its constraints, the committed tuned preset's margins and
// depths, and the refusals.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include "analysis/bench_run.hpp"
#include "analysis/impact_command.hpp"
#include "analysis/loop_model.hpp"
#include "analysis/pose_schedule.hpp"
#include "analysis/quiet_command.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"
#include "test_util.hpp"
#include "yaml_style.hpp"
#include "tune/compensator_search.hpp"
#include "tune/tuned_file.hpp"
#include "tune/verification.hpp"

namespace robodamp {
namespace {

const std::string kJob = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml";

std::complex<double> polyval(const std::vector<double>& p, std::complex<double> s) {
  std::complex<double> v = 0.0;
  for (double a : p) v = v * s + a;
  return v;
}

TEST(Tune, TheRationalBlockIsMinimumPhaseStableAndUnityAtTheMatchFrequency) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  const tune::Candidate c{1000.0, 4.0, 0.3, 15.0, 0.2, 30.0, 0.5, -1};
  const config::Config cfg = tune::with_candidate(base, c);
  EXPECT_EQ(cfg.controller.gain_ns_per_m, 1000.0);
  EXPECT_EQ(cfg.controller.polarity, -1);
  const config::BlockConfig& b = cfg.controller.chain.back();
  ASSERT_EQ(b.model, config::CompensatorModel::kRational);
  ASSERT_EQ(b.numerator.size(), 4u);
  ASSERT_EQ(b.denominator.size(), 4u);
  for (double a : b.numerator) EXPECT_GT(a, 0.0);  // a real pole/zero and a damped pair: Hurwitz, all positive
  for (double a : b.denominator) EXPECT_GT(a, 0.0);
  const double fm = tune::unity_gain_hz(base);
  EXPECT_NEAR(fm, 9.2, 1e-9);
  const std::complex<double> s(0.0, 2.0 * M_PI * fm);
  EXPECT_NEAR(std::abs(polyval(b.numerator, s) / polyval(b.denominator, s)), 1.0, 1e-12);
  // The chain designs it at the loop rate.
  EXPECT_NO_THROW(analysis::LoopModel{cfg});
  config::Config no_comp = base;
  no_comp.controller.chain.pop_back();
  EXPECT_THROW((void)tune::with_candidate(no_comp, c), config::ConfigError);
}

// A set restated at another match frequency is the same controller: K times the unity-scaled compensator
// agrees at every frequency; K stays inside the search's range.
TEST(Tune, ASetRestatedAtAnotherMatchFrequencyIsTheSameController) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  const tune::Candidate c{1000.0, 4.0, 0.3, 15.0, 0.2, 30.0, 0.5, -1};
  const tune::Candidate moved = tune::restated(c, 9.2, 18.0);
  EXPECT_NE(moved.gain_ns_per_m, c.gain_ns_per_m);
  const config::BlockConfig& comp = base.controller.chain.back();
  const config::BlockConfig a = tune::compensator_block(c, comp, 9.2), b = tune::compensator_block(moved, comp, 18.0);
  for (const double f : {1.0, 9.2, 18.0, 60.0}) {
    const std::complex<double> s(0.0, 2.0 * M_PI * f);
    const std::complex<double> ka = c.gain_ns_per_m * polyval(a.numerator, s) / polyval(a.denominator, s),
                               kb = moved.gain_ns_per_m * polyval(b.numerator, s) / polyval(b.denominator, s);
    EXPECT_NEAR(std::abs(kb - ka) / std::abs(ka), 0.0, 1e-9) << f << " Hz";
  }
  EXPECT_EQ(moved.polarity, c.polarity);
  for (const auto& [from, to] : {std::pair{1.0, 18.0}, std::pair{18.0, 1.0}}) {  // |C| differs there: one of each binds
    EXPECT_GE(tune::restated({tune::kGainMinNsPerM, 4.0, 0.3, 15.0, 0.2, 30.0, 0.5, 1}, from, to).gain_ns_per_m,
              tune::kGainMinNsPerM);
    EXPECT_LE(tune::restated({tune::kGainMaxNsPerM, 4.0, 0.3, 15.0, 0.2, 30.0, 0.5, 1}, from, to).gain_ns_per_m,
              tune::kGainMaxNsPerM);
  }
}

// The evaluation reproduces the analysis the issue quotes: C2 0.841 mm, C1 0.667 mm (K = 2000 N s/m), the
// open loop 0.324 mm; C2 sinks the 23.5 Hz mode's floor below the open loop's and leaves the damping window
// at 21 and 23.5 Hz, C1 does neither.
TEST(Tune, EvaluationMatchesTheAnalysisForC1AndC2) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  const tune::Evaluator evaluate(base, config::load_milling_config(kJob), {});
  EXPECT_NEAR(evaluate.open_min_depth_mm(), 0.324, 0.001);
  EXPECT_GE(evaluate.open_intervals_rpm().size(), 3u);
  const tune::Evaluation c2 = evaluate.assess(base);
  EXPECT_NEAR(c2.min_depth_mm, 0.841, 0.001);
  EXPECT_LT(c2.floor_ratio, 1.0);
  EXPECT_GT(c2.worst_mode_phase_deg, 90.0);  // C2 feeds 21 and 23.5 Hz back outside the damping window
  EXPECT_FALSE(c2.feasible());
  EXPECT_TRUE(c2.binding == "a lobe floor below the open loop's" || c2.binding == "a mode outside the damping window")
      << c2.binding;
  config::Config c1 = config::load_config_file(test::preset("horizontal_c1"));
  const tune::Evaluation e1 = evaluate.assess(c1);
  EXPECT_NEAR(e1.min_depth_mm, 0.667, 0.001);
  EXPECT_GE(e1.floor_ratio, 1.0);
  EXPECT_TRUE(e1.feasible()) << e1.binding;
  EXPECT_GE(e1.gain_margin_db, 6.0);
}

void expect_same_evaluation(const tune::Evaluation& a, const tune::Evaluation& b, const std::string& what) {
  EXPECT_EQ(a.stable, b.stable) << what;
  EXPECT_EQ(a.objective, b.objective) << what;
  EXPECT_EQ(a.violation, b.violation) << what;
  EXPECT_EQ(a.binding, b.binding) << what;
  EXPECT_EQ(a.k_max_ns_per_m, b.k_max_ns_per_m) << what;
  EXPECT_EQ(a.gain_margin_db, b.gain_margin_db) << what;
  EXPECT_EQ(a.phase_margin_deg, b.phase_margin_deg) << what;
  EXPECT_EQ(a.delay_margin_ms, b.delay_margin_ms) << what;
  EXPECT_EQ(a.quiet_command_rms_v, b.quiet_command_rms_v) << what;
  EXPECT_EQ(a.actuator_use, b.actuator_use) << what;
  EXPECT_EQ(a.min_depth_mm, b.min_depth_mm) << what;
  EXPECT_EQ(a.accurate_min_mm, b.accurate_min_mm) << what;
  EXPECT_EQ(a.depth_at_speed_mm, b.depth_at_speed_mm) << what;
  EXPECT_EQ(a.floors_mm, b.floors_mm) << what;
  EXPECT_EQ(a.peak_m_per_n, b.peak_m_per_n) << what;
}

// The search checks every plant's constraints first and scores a candidate only where they all hold; scoring
// it from where its check left it (Evaluator::finish) is its whole evaluation, to the bit: a stable candidate of
// each polarity and an unstable one, with the job and without. A candidate's loop runs on the plant the
// evaluator sampled once (its sweeps shared): the same evaluation, to the bit, as its configuration's own loop.
TEST(Tune, ACheckedCandidateFinishedIsItsWholeEvaluation) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  const tune::Evaluator with_job(base, config::load_milling_config(kJob), {}), alone(base, std::nullopt, {});
  const auto c1 = [&](double k, int polarity) {
    return tune::Candidate{k,       base.actuator.natural_freq_hz, base.actuator.damping_ratio, 0.5, 1.0, 10.0, 10.0,
                           polarity};
  };
  int stable = 0, unstable = 0;
  for (const tune::Evaluator* e : {&with_job, &alone})
    for (const tune::Candidate& c : {c1(2000.0, 1), c1(2000.0, -1), c1(4e5, 1)}) {
      const tune::Evaluation whole = (*e)(c), checked = (*e)(c, true), finished = e->finish(checked);
      const std::string what = std::string(e == &alone ? "no job" : "job") + ", K " + std::to_string(c.gain_ns_per_m) +
                               ", polarity " + std::to_string(c.polarity);
      expect_same_evaluation(finished, whole, what);
      expect_same_evaluation(e->assess(tune::with_candidate(base, c)), whole, what + ", its own loop");
      if (whole.stable && e == &with_job) {
        EXPECT_GT(whole.accurate_min_mm, 0.0) << what << ": the job scored";
      }
      if (!whole.stable) {
        EXPECT_EQ(finished.objective, checked.objective) << what << ": nothing to score";
      }
      ++(whole.stable ? stable : unstable);
    }
  EXPECT_GE(stable, 2);
  EXPECT_GE(unstable, 2);
}

// A short search: seeded, so it repeats exactly; feasible, and deeper than the open loop.
TEST(Tune, AShortSeededSearchRepeatsAndBeatsTheOpenLoopWithinItsConstraints) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  const auto job = config::load_milling_config(kJob);
  tune::TuneSettings s;
  s.global_evaluations = 30;
  s.local_evaluations = 10;
  const tune::TuneResult a = tune::tune(base, job, s), b = tune::tune(base, job, s);
  ASSERT_EQ(a.history.size(), 80u);
  ASSERT_EQ(b.history.size(), a.history.size());
  EXPECT_EQ(a.best.objective, b.best.objective);
  EXPECT_EQ(a.best.candidate.gain_ns_per_m, b.best.candidate.gain_ns_per_m);
  ASSERT_TRUE(a.best.feasible()) << a.best.binding;
  EXPECT_GT(a.best.min_depth_mm, 0.324);
  EXPECT_GE(a.best.gain_margin_db, s.gain_margin_min_db);
  EXPECT_GE(a.best.phase_margin_deg, s.phase_margin_min_deg);
  EXPECT_GE(a.best.floor_ratio, 1.0);
}

// Without a job the objective is the largest closed-loop peak: a short search lowers it below the open
// loop's (3.153e-5 m/N at the TCP) within the margins and the actuator's limits.
TEST(Tune, WithoutAJobTheSearchLowersTheClosedLoopPeak) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  tune::TuneSettings s;
  s.global_evaluations = 30;
  s.local_evaluations = 10;
  const tune::TuneResult r = tune::tune(base, std::nullopt, s);
  ASSERT_TRUE(r.best.feasible()) << r.best.binding;
  EXPECT_GT(r.best.peak_m_per_n, 0.0);
  EXPECT_LT(r.best.peak_m_per_n, 0.8 * 3.153e-5);
  EXPECT_NEAR(r.best.objective, -std::log10(r.best.peak_m_per_n), 1e-12);
  EXPECT_GT(r.best.actuator_use, 0.0);
  EXPECT_LT(r.best.actuator_use, 1.0);
  std::printf("no job: closed-loop peak %.4g m/N (open 3.153e-5), K %.0f N s/m, GM %.1f dB, PM %.1f deg\n",
              r.best.peak_m_per_n, r.best.candidate.gain_ns_per_m, r.best.gain_margin_db, r.best.phase_margin_deg);
}

// config/presets/tuned_horizontal.yaml and tuned_vertical.yaml are what the command in their header wrote
// (docs/tuning.md): their margins by the analysis of the file itself, and on the job: the depth at 700 rpm
// by the sampled loop's SDM at least the command's --depth-at-speed-mm, no open-loop SDM minimum sinking, every mode in the damping
// window, the command at the bench's impact within the actuator's limits. The depths the header promises are
// what the verification computes again, and they hold in the time-domain cut with the real Controller
// within 5 % (issue 27).
TEST(Tune, TheTunedPresetsHaveTheirMarginsAndDepths) {
  const config::MillingConfig job = config::load_milling_config(kJob);
  for (const char* preset : {"tuned_horizontal", "tuned_vertical"}) {
    const config::Config cfg = config::load_config_file(test::preset(preset));
    const analysis::LoopModel m(cfg);
    const analysis::AnalysisResult a = analysis::analyse(m);
    ASSERT_TRUE(a.stable) << preset;
    EXPECT_GE(*a.margins.gain_margin_db, 6.0 - 1e-6) << preset;
    EXPECT_GE(*a.margins.phase_margin_deg, 45.0) << preset;
    const std::string text = test::read_file(test::preset(preset));
    double target_mm = 0.0;
    ASSERT_EQ(std::sscanf(text.c_str() + text.find("--depth-at-speed-mm "), "--depth-at-speed-mm %lf", &target_mm), 1)
        << preset;
    const tune::Evaluator evaluate(cfg, job, {});
    const tune::Evaluation e = evaluate.assess(cfg);
    EXPECT_GE(e.depth_at_speed_mm, target_mm * (1.0 - 5e-3)) << preset;
    EXPECT_GE(e.open_minima_ratio, 1.0) << preset;
    for (const auto& mode : a.modes) EXPECT_TRUE(mode.damps) << preset << " " << mode.freq_hz << " Hz";
    EXPECT_LT(e.actuator_use, 1.0) << preset;
    // The header's promises, computed again and checked in time.
    double min_mm = 0, min_rpm = 0, at_mm = 0, at_rpm = 0, td_min = 0, td_at = 0;
    const std::size_t v = text.find("# Verified (sampled-loop SDM, ");
    ASSERT_NE(v, std::string::npos) << preset;
    ASSERT_EQ(std::sscanf(text.c_str() + text.find("damped minimum", v),
                          "damped minimum %lf mm at %lf rpm, %lf mm at the job's %lf rpm;", &min_mm, &min_rpm, &at_mm,
                          &at_rpm),
              4)
        << preset;
    ASSERT_EQ(std::sscanf(text.c_str() + text.find("Controller: ", v), "Controller: %lf mm and %lf mm there.", &td_min,
                          &td_at),
              2)
        << preset;
    const tune::Verification ver = tune::verify(cfg, job);
    std::printf("%s: verified minimum %.3f mm at %.1f rpm, %.3f mm at %.1f rpm; in time %.3f and %.3f mm\n", preset,
                ver.min_depth_mm, ver.min_rpm, ver.depth_at_speed_mm, ver.speed_rpm, ver.time_domain_at_min_mm,
                ver.time_domain_at_speed_mm);
    EXPECT_NEAR(ver.min_depth_mm, min_mm, 1.5e-3) << preset;
    EXPECT_NEAR(ver.min_rpm, min_rpm, 0.1) << preset;
    EXPECT_NEAR(ver.depth_at_speed_mm, at_mm, 1.5e-3) << preset;
    EXPECT_NEAR(td_min / min_mm, 1.0, 0.05) << preset;
    EXPECT_NEAR(td_at / at_mm, 1.0, 0.05) << preset;
    EXPECT_TRUE(ver.time_domain_agrees(0.05)) << preset;
    // Deeper than C2 (0.782 mm) at the job's speed; at the minimum the horizontal preset is not (0.353 mm for
    // C2's 0.478 mm, since the depth search finds the flip window at 374.5 rpm; docs/tuning.md).
    EXPECT_GT(ver.depth_at_speed_mm, 0.782) << preset << ": deeper than C2 at the job's speed";
  }
}

// The command the actuator-limit constraint predicts for the bench's impact (frequency domain, inverse FFT)
// against the bench's time-domain run of the real-time Controller on the simulated plant (with its sensor
// noise and the robot's drives on): the largest command within 10 %, for two compensators and both hammer
// locations, and for a hit hard enough to reach the limit the prediction says so and the bench saturates.
TEST(Tune, ThePredictedImpactCommandMatchesTheBench) {
  for (const char* preset : {"tuned_horizontal", "horizontal_c1"}) {
    const config::Config cfg = config::load_config_file(test::preset(preset));
    const analysis::LoopModel m(cfg);
    const analysis::Bench bench(cfg);
    analysis::ImpactCommand predict(m, cfg.bench.impact_peak_n, cfg.bench.impact_duration_ms * 1e-3);
    const double k = cfg.controller.gain_ns_per_m;
    const int pol = cfg.controller.polarity;
    double worst_measured = 0.0;
    for (std::size_t h = 0; h < m.plant().locations.size(); ++h) {
      analysis::ImpactTest t;
      t.excitation = h;
      t.peak_n = cfg.bench.impact_peak_n;
      t.duration_ms = cfg.bench.impact_duration_ms;
      t.control_on = true;
      t.gain_ns_per_m = k;
      t.polarity = pol;
      const analysis::ImpactTestResult r = bench.impact_test(t);
      EXPECT_EQ(r.saturation_time_s, 0.0) << preset;
      worst_measured = std::max(worst_measured, r.peak_command_v);
    }
    const analysis::CommandPeak p = predict.peak(m, k, pol);
    std::printf(
        "%s: impact %.0f N: predicted largest command %.3f V (%.1f N coil, %.0f V/s, tail %.3f), bench %.3f V\n",
        preset, cfg.bench.impact_peak_n, p.voltage_v, p.coil_force_n, p.slew_v_per_s, p.tail_fraction, worst_measured);
    EXPECT_NEAR(p.voltage_v, worst_measured, 0.1 * worst_measured) << preset;
    EXPECT_LT(p.tail_fraction, 0.01) << preset;
    // Hard enough that the linear command passes the force limit: the bench clips it.
    const double hard_n = cfg.bench.impact_peak_n * 1.5 * cfg.actuator.force_limit_n / p.coil_force_n;
    analysis::ImpactCommand hard(m, hard_n, cfg.bench.impact_duration_ms * 1e-3);
    EXPECT_GT(hard.peak(m, k, pol).coil_force_n, cfg.actuator.force_limit_n);
    analysis::ImpactTest t;
    t.excitation = p.location;
    t.peak_n = hard_n;
    t.duration_ms = cfg.bench.impact_duration_ms;
    t.control_on = true;
    t.gain_ns_per_m = k;
    t.polarity = pol;
    EXPECT_GT(bench.impact_test(t).saturation_time_s, 0.0) << preset;
  }
}

// The actuator-limit constraint in the evaluation: the preset's command at the bench's impact is a small
// share of the 36 N limit (within it); at 100 kN it passes the limit and the candidate is infeasible for that reason.
// A candidate whose command on a quiet cell reaches the supervisor's instability floor is refused: the
// first tuned_vertical.yaml (a slow, lightly damped compensator pole pair; its quiet command 0.10 V RMS
// against a 0.02 V floor) tripped "instability" after 22 s on a quiet cell (Loop.AQuietCommandAbove...).
TEST(Tune, TheQuietCommandIsAConstraint) {
  const config::Config slow = test::slow_pole_vertical();
  const config::MillingConfig job =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml");
  const tune::Evaluator evaluate(config::load_config_file(test::preset("vertical_c1")), job, {});
  const tune::Evaluation e = evaluate.assess(slow);
  EXPECT_TRUE(e.stable);
  EXPECT_NEAR(e.quiet_command_rms_v, 0.104, 0.005);
  EXPECT_FALSE(e.feasible());
  EXPECT_NE(e.binding.find("quiet cell's command"), std::string::npos) << e.binding;
  // The presets' controllers are far below a third of the floor.
  for (const char* name :
       {"horizontal_c1", "horizontal_c2", "horizontal_c3", "tuned_horizontal", "tuned_vertical", "vertical_c1"}) {
    const config::Config c = config::load_config_file(test::preset(name));
    EXPECT_LT(analysis::quiet_command(analysis::LoopModel(c), c.controller.gain_ns_per_m, c.controller.polarity).rms_v,
              c.supervision.instability_floor_v / 3.0)
        << name;
  }
}

TEST(Tune, TheActuatorLimitAtTheImpactIsAConstraint) {
  const config::Config cfg = config::load_config_file(test::preset("tuned_horizontal"));
  const tune::Evaluation nominal = tune::Evaluator(cfg, std::nullopt, {}).assess(cfg);
  EXPECT_GT(nominal.actuator_use, 0.05);
  EXPECT_LT(nominal.actuator_use, 1.0);  // the constraint: within the limits
  EXPECT_NEAR(nominal.peak_coil_force_n, nominal.peak_command_v * cfg.actuator.constant_n_per_v, 1e-9);
  tune::TuneSettings s;
  s.impact_peak_n = 100000.0;
  const tune::Evaluation hard = tune::Evaluator(cfg, std::nullopt, s).assess(cfg);
  EXPECT_NEAR(hard.actuator_use, 100.0 * nominal.actuator_use, 1e-6 * hard.actuator_use);  // linear in the impact
  EXPECT_FALSE(hard.feasible());
  EXPECT_EQ(hard.binding, "the actuator's limits at the impact");
  s.impact_peak_n = 0.0;  // no such constraint
  EXPECT_EQ(tune::Evaluator(cfg, std::nullopt, s).assess(cfg).actuator_use, 0.0);
}

// --no-worse-mode: a set that makes a robot mode's peak worse than open loop violates it by the shortfall, with the
// same improvement analysis::mode_improvements computes (the pose schedule preset's stretched set at the pose
// where it makes the 9.2 Hz mode worst); without the setting the same candidate is not bound by it.
TEST(Tune, AModeWorseThanOpenLoopIsAConstraintWhenAsked) {
  const config::Config preset = config::load_config_file(test::preset("pose_scheduled_c2"));
  const analysis::PoseScheduleAnalysis ps = analysis::analyse_pose_schedule(preset);
  const analysis::RegionSet& stretched = ps.regions.at(1);
  config::Config at = analysis::config_at_pose(
      stretched.config, analysis::pose_modes(ps.model, stretched.worst_mode_pose_deg, preset.pose_schedule->axis,
                                             preset.pose_schedule->modes));
  at.pose_schedule.reset();
  const tune::Evaluation free = tune::Evaluator(at, std::nullopt, {}).assess(at);
  EXPECT_EQ(free.binding.find("worse than open loop"), std::string::npos) << free.binding;
  tune::TuneSettings s;
  s.no_worse_mode = true;
  const tune::Evaluation bound = tune::Evaluator(at, std::nullopt, s).assess(at);
  EXPECT_FALSE(bound.feasible());
  EXPECT_NEAR(bound.worst_mode_improvement_pct, stretched.worst_mode_improvement_pct, 1e-9);
  EXPECT_LT(bound.worst_mode_improvement_pct, -20.0);
  // Its share of the violation: the improvement's shortfall in units of 100 %.
  EXPECT_NEAR(bound.violation - free.violation, -bound.worst_mode_improvement_pct / 100.0, 1e-9);
}

// Several plants: the worst case is each quantity's worst over the plants, and a violation is named with
// its plant. Shifted modes keep the nominal's controller (the compensator identical) and move the lobes.
TEST(Tune, TheRobustEvaluationKeepsTheWorstCaseOverThePlants) {
  const config::Config h = config::load_config_file(test::preset("horizontal_c2"));
  const config::Config v = config::load_config_file(test::preset("vertical_c1"));
  const auto job = config::load_milling_config(kJob);
  const tune::Evaluator eh(h, job, {}, "horizontal"), ev(v, job, {}, "vertical");
  const tune::Candidate c{2000.0, h.actuator.natural_freq_hz, h.actuator.damping_ratio, 0.5, 1.0, 10.0, 10.0, -1};
  const tune::Evaluation w = tune::evaluate_worst({&eh, &ev}, c);
  ASSERT_EQ(w.per_plant.size(), 2u);
  EXPECT_EQ(w.per_plant[0].plant, "horizontal");
  EXPECT_EQ(w.per_plant[1].plant, "vertical");
  EXPECT_EQ(w.min_depth_mm, std::min(w.per_plant[0].min_depth_mm, w.per_plant[1].min_depth_mm));
  EXPECT_EQ(w.gain_margin_db, std::min(w.per_plant[0].gain_margin_db, w.per_plant[1].gain_margin_db));
  EXPECT_EQ(w.actuator_use, std::max(w.per_plant[0].actuator_use, w.per_plant[1].actuator_use));
  EXPECT_EQ(w.feasible(), w.per_plant[0].feasible() && w.per_plant[1].feasible());
  if (!w.feasible()) {
    EXPECT_EQ(w.binding.rfind(w.plant + ": ", 0), 0u) << w.binding;
  }
  const config::Config up = tune::with_shifted_modes(h, 1.1);
  EXPECT_NEAR(tune::unity_gain_hz(up), tune::unity_gain_hz(h), 1e-12);
  EXPECT_EQ(tune::with_candidate(up, c).controller.chain.back().numerator,
            tune::with_candidate(h, c).controller.chain.back().numerator);
  const analysis::LoopModel m_up(up), m(h);
  const double f_open = 9.2;
  EXPECT_LT(std::abs(m_up.open_continuous(0, 0, 1.1 * f_open)), 1.2 * std::abs(m.open_continuous(0, 0, f_open)));
  EXPECT_GT(std::abs(m_up.open_continuous(0, 0, 1.1 * f_open)), 0.8 * std::abs(m.open_continuous(0, 0, f_open)));
  const tune::Evaluator e_up(up, job, {}, "up");
  EXPECT_GT(std::abs(e_up.open_min_depth_mm() - eh.open_min_depth_mm()), 0.01);
}

// The tuned presets on their robot with every mode 5 % lower and higher (the controller unchanged): still
// stable, every mode still damped, the gain margin above 3 dB. Their depths on the shifted robot are printed
// (docs/tuning.md quotes them); the presets were tuned for the nominal robot only, so the 6 dB / 45 deg and
// depth targets are not asserted there.
TEST(Tune, TheTunedPresetsStayStableWithModesShiftedFivePercent) {
  const auto job = config::load_milling_config(kJob);
  for (const char* preset : {"tuned_horizontal", "tuned_vertical"}) {
    const config::Config cfg = config::load_config_file(test::preset(preset));
    for (const double factor : {0.95, 1.05}) {
      const config::Config shifted = tune::with_shifted_modes(cfg, factor);
      const tune::Evaluation e = tune::Evaluator(shifted, job, {}).assess(shifted);
      std::printf(
          "%s, modes x%.2f: stable %d, GM %.1f dB, PM %.1f deg, worst mode %.0f deg, min depth %.3f mm "
          "(open %.3f), %.3f mm at 700 rpm, floors x%.2f\n",
          preset, factor, e.stable, e.gain_margin_db, e.phase_margin_deg, e.worst_mode_phase_deg, e.min_depth_mm,
          tune::Evaluator(shifted, job, {}).open_min_depth_mm(), e.depth_at_speed_mm, e.floor_ratio);
      EXPECT_TRUE(e.stable) << preset << " x" << factor;
      EXPECT_LT(e.worst_mode_phase_deg, 90.0) << preset << " x" << factor;
      EXPECT_GT(e.gain_margin_db, 3.0) << preset << " x" << factor;
    }
  }
}

// The bench run with each tuned preset: measured improvement within 5 % of the analysis on every FRF and no
// saturation at the bench's nominal impacts (the issue's acceptance; robodamp bench prints the same).
TEST(Tune, TheTunedPresetsPassTheBench) {
  for (const char* preset : {"tuned_horizontal", "tuned_vertical"}) {
    const analysis::BenchReport rep = analysis::Bench(config::load_config_file(test::preset(preset))).run();
    EXPECT_TRUE(rep.improvement_within_5pct) << preset << ": " << rep.verdict;
    int nominal = 0;
    for (const auto& row : rep.rows)
      if (row.kind == "nominal") {
        ++nominal;
        EXPECT_FALSE(row.saturated) << preset << " " << row.name;
        ASSERT_TRUE(row.measured_improvement_pct && row.predicted_improvement_pct);
        std::printf("%s %s: measured %.1f %%, predicted %.1f %%\n", preset, row.name.c_str(),
                    *row.measured_improvement_pct, *row.predicted_improvement_pct);
      }
    EXPECT_EQ(nominal, 3) << preset;
  }
}

TEST(Tune, TheTunedControllerHoldsItsDepthsInTheSimulatedCut) {
  // The tuned horizontal preset on the job (config/milling/active_damping_tuned.yaml): at the speeds of the
  // open loop's lobes (252 rpm) and C2's worst 23.5 Hz lobe (672 rpm), the simulated cut with the real
  // Controller agrees with the sampled loop's SDM within 5 %, and at the job's 700 rpm the tuned controller
  // cuts more than 1.5 times as deep as C2 (1.50 mm against 0.78 mm, docs/tuning.md).
  auto limits = [](const std::string& job_path, double rpm, double revolutions, double* sdm_mm) {
    const config::MillingConfig cfg = config::load_milling_config(job_path);
    const config::StructureConfig& st = *cfg.find_structure(cfg.structure);
    const milling::Structure open(st, false), damped(st, true);
    const auto process = milling::chatter_process(cfg.tool, cfg.material, cfg.cut);
    const double zoa = milling::LobeModel(damped, process, cfg.lobes).critical_depth_mm(rpm);
    *sdm_mm = milling::AccurateStability(damped, cfg).critical(rpm, zoa).critical_depth_mm;
    milling::CutOverrides ov;
    ov.rpm = rpm;
    ov.damped = true;
    ov.revolutions = revolutions;
    const milling::CutJob job = milling::make_cut_job(cfg, open, ov);
    return milling::critical_depth(job.dynamics, job.cutter, job.material, job.settings, *sdm_mm, 2e-3).depth_mm;
  };
  const std::string tuned = std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_tuned.yaml";
  // At 252 rpm the critical motion is the 9.4 Hz mode, which grows slowly near the limit: 300 revolutions
  // (71 s) call 0.86 mm stable, 1500 revolutions find its Hopf chatter.
  for (const auto& [rpm, revolutions] : {std::pair{252.0, 1500.0}, std::pair{672.0, 300.0}}) {
    double sdm = 0.0;
    const double t = limits(tuned, rpm, revolutions, &sdm);
    std::printf("%.0f rpm: tuned %.3f mm simulated, %.3f mm sampled-loop SDM\n", rpm, t, sdm);
    EXPECT_NEAR(t / sdm, 1.0, 0.05) << rpm << " rpm";
  }
  double sdm_tuned = 0.0, sdm_c2 = 0.0;
  const double t700 = limits(tuned, 700.0, 300.0, &sdm_tuned), c2_700 = limits(kJob, 700.0, 300.0, &sdm_c2);
  EXPECT_GT(t700, 1.5 * c2_700) << "700 rpm: tuned " << t700 << " mm, C2 " << c2_700 << " mm";
}

TEST(Tune, AJobWithoutADampingLocationIsRefused) {
  const config::Config base = config::load_config_file(test::preset("horizontal_c2"));
  auto job =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/industrial_robot_aluminium.yaml");
  try {
    const tune::Evaluator e(base, job, {});
    ADD_FAILURE() << "accepted";
  } catch (const config::ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("has no damping location"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace robodamp

namespace robodamp {
using test::in_style;

// The file tune writes, from every preset with a compensator, as written, in block style (as identify all
// writes) and in flow style: it parses, has the candidate's compensator, gain and polarity, and everything
// else of the configuration unchanged; the presets' comments outside the edited values are kept (issue 29).
TEST(Tune, TheTunedFileReadsBackFromEveryPresetInEveryStyle) {
  tune::Candidate c;
  c.gain_ns_per_m = 1234.5;
  c.fz_hz = 9.0, c.zeta_z = 0.3, c.fp_hz = 2.0, c.zeta_p = 0.7, c.fa_hz = 12.0, c.fb_hz = 30.0;
  c.polarity = -1;
  int files = 0;
  for (const char* name : {"horizontal_c1", "horizontal_c2", "horizontal_c3", "vertical_c1", "tuned_horizontal",
                           "tuned_vertical", "pose_scheduled_c2"}) {
    const std::string original = test::read_file(test::preset(name));
    for (const auto& [style, text] :
         {std::pair{"as written", original}, std::pair{"block", in_style(original, YAML::EmitterStyle::Block)},
          std::pair{"flow", in_style(original, YAML::EmitterStyle::Flow)}}) {
      const config::Config base = config::parse_config(text, test::preset(name));  // relative paths from there
      const config::Config want = tune::with_candidate(base, c);
      const config::EditedYaml out = tune::tuned_config_text(base, c);
      EXPECT_TRUE(out.comments_kept) << name << " " << style;
      const config::Config got = config::parse_config(out.text, test::preset(name));
      EXPECT_EQ(got.controller.gain_ns_per_m, want.controller.gain_ns_per_m) << name << " " << style;
      EXPECT_EQ(got.controller.polarity, -1) << name << " " << style;
      EXPECT_FALSE(got.controller.speed_schedule)
          << name << " " << style << ": the schedule chose K for the chain replaced";
      ASSERT_EQ(got.controller.chain.size(), want.controller.chain.size()) << name << " " << style;
      for (std::size_t i = 0; i < got.controller.chain.size(); ++i) {
        const auto& g = got.controller.chain[i];
        const auto& w = want.controller.chain[i];
        EXPECT_EQ(g.kind, w.kind) << name << " " << style << " " << i;
        EXPECT_EQ(g.model, w.model) << name << " " << style << " " << i;
        ASSERT_EQ(g.numerator.size(), w.numerator.size()) << name << " " << style << " " << i;
        for (std::size_t k = 0; k < g.numerator.size(); ++k) EXPECT_DOUBLE_EQ(g.numerator[k], w.numerator[k]);
        for (std::size_t k = 0; k < g.denominator.size(); ++k) EXPECT_DOUBLE_EQ(g.denominator[k], w.denominator[k]);
        EXPECT_EQ(g.cutoff_hz, w.cutoff_hz) << name << " " << style << " " << i;
        EXPECT_EQ(g.center_hz, w.center_hz) << name << " " << style << " " << i;
      }
      // The rest of the configuration is the base's.
      EXPECT_EQ(got.loop.rate_hz, base.loop.rate_hz);
      EXPECT_EQ(got.actuator.delay_s, base.actuator.delay_s);
      EXPECT_EQ(got.controller.match_freq_hz, base.controller.match_freq_hz);
      EXPECT_EQ(got.controller.gain_ramp_s, base.controller.gain_ramp_s);
      if (std::string(style) == "as written") {
        for (const char* comment : {"# Published parameters", "# Eq. 15"})
          if (original.find(comment) != std::string::npos) {
            EXPECT_NE(out.text.find(comment), std::string::npos) << name << ": " << comment;
          }
      }
      ++files;
    }
  }
  EXPECT_EQ(files, 21);
}
}  // namespace robodamp

namespace robodamp {
namespace {

// The numbers of a tune header's "Verified" lines: the minimum, its speed, the depth at the job's speed, that
// speed, and the time-domain cut's two depths.
std::vector<double> tune_promises(const std::string& text) {
  std::vector<double> out;
  const auto from = text.find("# Verified (", text.find("# robodamp tune wrote this"));
  const auto to = text.find(" there.", from);
  const std::string block = text.substr(from, to - from);
  const std::regex number(R"([0-9]+\.[0-9]+)");
  for (auto it = std::sregex_iterator(block.begin(), block.end(), number); it != std::sregex_iterator(); ++it)
    out.push_back(std::stod(it->str()));
  return out;
}

// The search resumes from a file robodamp tune wrote: its compensator read back as the candidate gives the
// same controller (the same loop, the same K), and a preset in C1's form has none.
TEST(Tune, ACandidateReadBackFromATunedFileIsTheSameController) {
  const config::Config tuned = config::load_config_file(test::preset("tuned_horizontal"));
  const auto c = tune::candidate_of(tuned);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->polarity, tuned.controller.polarity);
  EXPECT_DOUBLE_EQ(c->gain_ns_per_m, tuned.controller.gain_ns_per_m);
  const config::Config again = tune::with_candidate(tuned, *c);
  const analysis::LoopModel a(tuned), b(again);
  for (const double f_hz : {1.0, 9.2, 21.0, 23.5, 100.0})
    EXPECT_NEAR(std::abs(b.chain().chain_digital(f_hz) / a.chain().chain_digital(f_hz) - 1.0), 0.0, 1e-9)
        << f_hz << " Hz";
  EXPECT_FALSE(tune::candidate_of(config::load_config_file(test::preset("horizontal_c1"))));
}

// Each tuned preset's recorded command (the line after "# robodamp tune wrote this") run again writes the same
// promises within 1 %: the minimum and the depth at the job's speed, by the accurate method and in time.
TEST(Tune, EachTunedPresetsRecordedCommandWritesItAgain) {
  const std::string dir = ::testing::TempDir() + "robodamp_tune_rerun_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  for (const std::string name : {"tuned_horizontal", "tuned_vertical"}) {
    const std::string text = test::read_file(test::preset(name));
    std::string why;
    const std::string out = test::rerun_recorded_command(text, "# robodamp tune wrote this", "tune", dir, name, why);
    ASSERT_FALSE(out.empty()) << name << ": " << why;
    const std::vector<double> was = tune_promises(text), now = tune_promises(test::read_file(out));
    ASSERT_EQ(was.size(), 6U) << name;
    ASSERT_EQ(now.size(), was.size()) << name;
    for (std::size_t i = 0; i < was.size(); ++i)
      EXPECT_NEAR(now[i], was[i], 0.01 * std::abs(was[i])) << name << " #" << i;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace robodamp
