// Bench::run: the runs of the bench scheduled on a few threads and the report assembled from them.
// The runs are independent (each has its own plant, controller, sensors and seeds); the report is built
// from their results in the serial order afterwards, so it is the same byte for byte for any number of
// threads (tests/test_bench.cpp: ParallelRunIsTheSerialRun). docs/simulation.md, "Main job".
#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>

#include "analysis/bench_run.hpp"
#include "analysis/task_pool.hpp"

namespace robodamp::analysis {

namespace {

std::string fixed(double v, int digits) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

// Passes progress lines on in their serial order, whichever run finishes first.
class OrderedProgress {
 public:
  OrderedProgress(const Progress& progress, std::size_t lines) : progress_(progress), lines_(lines), ready_(lines) {}
  void post(std::size_t i, std::string line) {
    const std::lock_guard<std::mutex> lock(mutex_);
    lines_[i] = std::move(line);
    ready_[i] = true;
    for (; next_ < lines_.size() && ready_[next_]; ++next_)
      if (progress_) progress_(lines_[next_]);
  }

 private:
  const Progress& progress_;
  std::mutex mutex_;
  std::vector<std::string> lines_;
  std::vector<bool> ready_;
  std::size_t next_{0};
};

}  // namespace

std::string Bench::test_line(int number, int tests, const ImpactTest& t, const std::string& what,
                             const ImpactTestResult& r) const {
  return "impact test " + std::to_string(number) + "/" + std::to_string(tests) + ": " + what + ", " +
         std::to_string(cfg_.bench.averages) + " x " + fixed(t.peak_n, 0) + " N (" + fixed(t.duration_ms, 1) +
         " ms) at " + model_.plant().locations[t.excitation].name + ": " + fixed(r.simulated_s, 1) +
         " s simulated in " + fixed(r.wall_s, 2) + " s";
}

BenchRow Bench::make_row(const AnalysisResult& an, std::size_t i, const ImpactTestResult& open_r,
                         const ImpactTestResult& closed_r, double peak_n, const std::string& kind, double k,
                         const FrfResult* predicted, const FrfResult* predicted_c) const {
  const double lo = cfg_.analysis.band_min_hz, hi = cfg_.analysis.band_max_hz;
  const auto& f = an.frfs_discrete[i];
  BenchRow row;
  row.name = f.name;
  row.kind = kind;
  row.gain_ns_per_m = k;
  row.impact_peak_n = peak_n;
  row.open = measured_peak(open_r.receptance[f.response], lo, hi);
  row.closed = measured_peak(closed_r.receptance[f.response], lo, hi);
  row.measured_improvement_pct = (row.open.magnitude_m_per_n / row.closed.magnitude_m_per_n - 1.0) * 100.0;
  if (predicted) row.predicted_improvement_pct = predicted->improvement_pct;
  if (predicted_c) row.predicted_continuous_improvement_pct = predicted_c->improvement_pct;
  row.saturation_time_s = closed_r.saturation_time_s;
  row.saturated = closed_r.saturation_time_s > 0.0;
  row.peak_actuator_force_n = closed_r.peak_actuator_force_n;
  row.coherence_min = std::min(row.open.coherence_min, row.closed.coherence_min);
  return row;
}

std::string Bench::verdict(const BenchReport& rep) const {
  const auto& an = rep.analysis;
  std::ostringstream v;
  const BenchRow* dp_row = nullptr;
  for (const auto& r : rep.rows)
    if (r.kind == "nominal") dp_row = &r;
  v << (rep.improvement_within_5pct && rep.sweep_agrees ? "PASS" : "MISMATCH") << ": measured improvement "
    << (rep.improvement_within_5pct ? "within" : "NOT within") << " 5 % of the analysis on all "
    << an.frfs_discrete.size() << " FRFs";
  if (dp_row)
    v << " (" << dp_row->name << " " << fixed(*dp_row->measured_improvement_pct, 1) << " % measured, "
      << fixed(*dp_row->predicted_improvement_pct, 1) << " % predicted)";
  if (an.max_stable_gain_ns_per_m)
    v << "; gain sweep " << (rep.sweep_agrees ? "agrees" : "DISAGREES")
      << " with K_max = " << fixed(*an.max_stable_gain_ns_per_m, 0) << " N s/m";
  double sat_min = 1e300;
  for (const auto& r : rep.rows)
    if (r.kind == "saturating") sat_min = std::min(sat_min, *r.measured_improvement_pct);
  if (sat_min < 1e300)
    v << "; " << fixed(cfg_.bench.saturating_impact_peak_n, 0) << " N impacts saturate the "
      << fixed(model_.plant().actuator.force_limit_n, 0) << " N actuator and cut the improvement to "
      << fixed(sat_min, 1) << " %";
  return v.str();
}

// One gain of the sweep: the divergence run and, below the predicted limit, an impact test at the
// actuator's driving point with the improvement the analysis predicts there.
struct BenchSweepRun {
  DivergenceRun run;
  std::optional<ImpactTestResult> impact;
  std::vector<FrfResult> predicted, predicted_continuous;
};

// What the phases of a bench run share: the impact locations the configured FRFs need, the tests' results
// per location, the sweep's runs, the progress and the report being filled.
struct Bench::RunState {
  const Progress& progress;
  std::size_t threads;
  BenchReport rep{};
  std::vector<std::size_t> locations{};  // in the order the analysis lists the FRFs' excitations
  std::vector<ImpactTestResult> off{}, on{}, sat{};
  std::vector<double> factors{};  // of K_max, the gain sweep's
  std::vector<BenchSweepRun> sweep{};
  std::optional<std::size_t> dp{};  // the actuator's driving-point FRF
  int tests{0};
  [[nodiscard]] std::size_t index_of(std::size_t excitation) const {
    return static_cast<std::size_t>(std::find(locations.begin(), locations.end(), excitation) - locations.begin());
  }
};

namespace {

ImpactTest test_at(const config::BenchConfig& b, std::size_t location, bool on, bool saturating, double k, int pol) {
  return ImpactTest{location,
                    saturating ? b.saturating_impact_peak_n : b.impact_peak_n,
                    saturating ? b.saturating_impact_duration_ms : b.impact_duration_ms,
                    on,
                    on ? k : 0.0,
                    pol};
}

}  // namespace

// The analysis and the open-loop tests, which do not need it, in parallel; the open loop's measured peaks.
void Bench::run_open(RunState& st) const {
  const double gain = cfg_.controller.gain_ns_per_m;
  const int pol = cfg_.controller.polarity;
  const std::size_t nl = st.locations.size();
  st.off.resize(nl), st.on.resize(nl), st.sat.resize(nl);
  std::vector<std::function<void()>> first{[&] { st.rep.analysis = analyse(model_, gain, pol); }};
  for (std::size_t i = 0; i < nl; ++i)
    first.emplace_back(
        [&, i] { st.off[i] = impact_test(test_at(cfg_.bench, st.locations[i], false, false, 0.0, pol)); });
  run_tasks(first, st.threads);
  const auto& an = st.rep.analysis;
  st.tests = static_cast<int>(nl) * (an.stable ? 3 : 1);
  for (std::size_t i = 0; i < nl; ++i) {
    st.rep.simulated_s += st.off[i].simulated_s;
    if (st.progress)
      st.progress(test_line(static_cast<int>(i) + 1, st.tests,
                            test_at(cfg_.bench, st.locations[i], false, false, 0.0, pol), "control off", st.off[i]));
  }
  const double lo = cfg_.analysis.band_min_hz, hi = cfg_.analysis.band_max_hz;
  for (const auto& f : an.frfs_discrete) {
    const MeasuredPeak p = measured_peak(st.off[st.index_of(f.excitation)].receptance[f.response], lo, hi);
    st.rep.open_loop.push_back({f.name, f.open_peak_m_per_n, p.magnitude_m_per_n,
                                20.0 * std::log10(p.magnitude_m_per_n / f.open_peak_m_per_n), p.coherence_min});
  }
}

// The closed-loop tests (nominal and saturating) and the gain sweep across the predicted limit, in
// parallel, their progress lines in the serial run's order.
void Bench::run_closed(RunState& st) const {
  const double gain = cfg_.controller.gain_ns_per_m;
  const int pol = cfg_.controller.polarity;
  const auto& b = cfg_.bench;
  const auto& an = st.rep.analysis;
  const std::size_t nl = st.locations.size(), act = model_.actuator_location();
  for (std::size_t i = 0; i < an.frfs_discrete.size(); ++i)
    if (an.frfs_discrete[i].response == act && an.frfs_discrete[i].excitation == act) st.dp = i;
  st.factors = an.max_stable_gain_ns_per_m ? b.sweep_gain_factors : std::vector<double>{};
  st.sweep.resize(st.factors.size());
  OrderedProgress ordered(st.progress, 2 * nl + st.factors.size());
  std::vector<std::function<void()>> second;
  for (std::size_t i = 0; i < nl; ++i) {
    second.emplace_back([&, i] {
      const ImpactTest t = test_at(b, st.locations[i], true, false, gain, pol);
      st.on[i] = impact_test(t);
      ordered.post(i, test_line(static_cast<int>(nl + i) + 1, st.tests, t, "control on", st.on[i]));
    });
    second.emplace_back([&, i] {
      const ImpactTest t = test_at(b, st.locations[i], true, true, gain, pol);
      st.sat[i] = impact_test(t);
      ordered.post(nl + i,
                   test_line(static_cast<int>(2 * nl + i) + 1, st.tests, t, "control on, saturating", st.sat[i]));
    });
  }
  for (std::size_t j = 0; j < st.factors.size(); ++j)
    second.emplace_back([&, j] {
      const double k = st.factors[j] * *an.max_stable_gain_ns_per_m;
      BenchSweepRun& sp = st.sweep[j];
      sp.run = divergence_run(k, pol);
      ordered.post(2 * nl + j, "gain sweep K = " + fixed(k, 0) + " N s/m (" + fixed(st.factors[j], 2) +
                                   " x K_max): predicted " + (sp.run.predicted_unstable ? "unstable" : "stable") +
                                   ", simulated " + (sp.run.diverged ? "diverges" : "decays") + " (end/start RMS " +
                                   fixed(sp.run.growth_ratio, 3) + ")");
      if (st.dp && !sp.run.predicted_unstable) {
        sp.impact = impact_test({act, b.impact_peak_n, b.impact_duration_ms, true, k, pol});
        sp.predicted = improvements(model_, k, pol, true);
        sp.predicted_continuous = improvements(model_, k, pol, false);
      }
    });
  run_tasks(second, st.threads);
  for (std::size_t i = 0; i < nl; ++i) st.rep.simulated_s += st.on[i].simulated_s;
  for (std::size_t i = 0; i < nl; ++i) st.rep.simulated_s += st.sat[i].simulated_s;
}

// The closed-loop rows (nominal within 5 % of the prediction, saturating) and the sweep's rows and verdicts.
void Bench::report_closed(RunState& st) const {
  const double gain = cfg_.controller.gain_ns_per_m;
  const auto& b = cfg_.bench;
  const auto& an = st.rep.analysis;
  BenchReport& rep = st.rep;
  bool within = true;
  for (std::size_t i = 0; i < an.frfs_discrete.size(); ++i) {
    const std::size_t li = st.index_of(an.frfs_discrete[i].excitation);
    BenchRow row = make_row(an, i, st.off[li], st.on[li], b.impact_peak_n, "nominal", gain, &an.frfs_discrete[i],
                            &an.frfs_continuous[i]);
    within = within && std::abs(*row.measured_improvement_pct - *row.predicted_improvement_pct) <=
                           0.05 * std::abs(*row.predicted_improvement_pct);
    rep.rows.push_back(row);
  }
  for (std::size_t i = 0; i < an.frfs_discrete.size(); ++i) {
    const std::size_t li = st.index_of(an.frfs_discrete[i].excitation);
    rep.rows.push_back(make_row(an, i, st.off[li], st.sat[li], b.saturating_impact_peak_n, "saturating", gain,
                                &an.frfs_discrete[i], &an.frfs_continuous[i]));
  }
  rep.improvement_within_5pct = within;
  rep.sweep_agrees = true;
  if (st.factors.empty()) rep.notes.push_back("no gain sweep: the loop is stable up to the product's gain limit");
  const std::size_t act = model_.actuator_location();
  for (BenchSweepRun& sp : st.sweep) {
    DivergenceRun& d = sp.run;
    rep.simulated_s += b.sweep_duration_s;
    rep.sweep_agrees = rep.sweep_agrees && d.diverged == d.predicted_unstable;
    if (sp.impact) {
      rep.simulated_s += sp.impact->simulated_s;
      rep.rows.push_back(make_row(an, *st.dp, st.off[st.index_of(act)], *sp.impact, b.impact_peak_n, "sweep",
                                  d.gain_ns_per_m, &sp.predicted[*st.dp], &sp.predicted_continuous[*st.dp]));
    } else if (st.dp) {
      BenchRow row;
      row.name = an.frfs_discrete[*st.dp].name;
      row.kind = "sweep";
      row.gain_ns_per_m = d.gain_ns_per_m;
      row.impact_peak_n = b.impact_peak_n;
      row.saturated = d.saturation_time_s > 0.0;
      row.saturation_time_s = d.saturation_time_s;
      row.peak_actuator_force_n = d.peak_actuator_force_n;
      rep.rows.push_back(row);
    }
    rep.sweep.push_back(std::move(d));
  }
}

// The analysis and the open-loop tests; unless the loop is unstable, the closed-loop tests and the sweep;
// the report with its verdict.
BenchReport Bench::run(const Progress& progress, std::size_t jobs) const {
  const auto wall0 = std::chrono::steady_clock::now();
  RunState st{.progress = progress, .threads = task_threads(jobs)};
  st.rep.config = cfg_.source;
  const double gain = cfg_.controller.gain_ns_per_m;
  if (progress)
    progress("analysing the loop (K = " + fixed(gain, 0) + " N s/m, polarity " +
             std::to_string(cfg_.controller.polarity) + ")");
  // Which impact locations the configured FRFs need (the analysis lists the FRFs in this order too).
  for (const auto& f : cfg_.robot.frfs) {
    const std::size_t e = model_.plant().index_of(f.excitation_location);
    if (std::find(st.locations.begin(), st.locations.end(), e) == st.locations.end()) st.locations.push_back(e);
  }
  run_open(st);
  const auto& an = st.rep.analysis;
  if (!an.stable) {
    st.rep.verdict = "UNSTABLE: the analysis finds the loop unstable at K = " + fixed(gain, 0) +
                     " N s/m (spectral radius " + fixed(an.spectral_radius, 6) + "); closed-loop tests were not run";
    st.rep.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return st.rep;
  }
  st.rep.ran_closed_loop = true;
  run_closed(st);
  report_closed(st);
  st.rep.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  st.rep.verdict = verdict(st.rep);
  return st.rep;
}

}  // namespace robodamp::analysis
