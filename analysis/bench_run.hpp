// The bench run: the real-time Controller object against the simulated plant on a virtual clock at the
// loop rate, measured the way the paper measured it (docs/physics.md §1): averaged impact tests
// with control off and on, H1 receptance estimates, dynamic stiffness improvement, next to what the
// loop analysis predicts; a saturating excitation; and a gain sweep across the predicted stability limit.
// Off the real-time path (it allocates its records), but the per-tick loop body is the RT code path.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/loop_model.hpp"
#include "analysis/spectral.hpp"
#include "control/controller_params.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/sensor.hpp"

namespace robodamp::analysis {

struct ImpactTest {
  std::size_t excitation{0};  // location index
  double peak_n{1000.0};
  double duration_ms{1.0};
  bool control_on{false};
  double gain_ns_per_m{0.0};
  int polarity{1};
};

struct ImpactTestResult {
  std::vector<FrfEstimate> receptance;  // per response location (measurement accelerometers, H1 / -w^2)
  double peak_actuator_force_n{0.0};
  double peak_command_v{0.0};     // largest |command| the controller sent (after its limits)
  double saturation_time_s{0.0};  // loop ticks at a controller or actuator limit
  double simulated_s{0.0};
  double wall_s{0.0};
  bool finite{true};
};

// The measuring side of an impact test on a plant someone else steps, tick by tick (the bench steps it
// in process; the HIL emulator steps it for a controller in another process): `averages` hammer hits at
// irregular, seeded intervals from the start on, the measurement accelerometers at every location, and
// the H1 receptance over the whole records (rectangular window, zero-padded). The records are stored
// as they come and transformed at the end: the per-tick calls only write samples (the emulator's
// real-time pacing cannot stall for an FFT), and nothing is allocated after construction.
class ImpactCampaign {
 public:
  // Allocates the records.
  ImpactCampaign(const config::Config& cfg, sim::Plant& plant, const ImpactTest& t);
  // Adds the hammer with its hits from start_s on (plant time = tick / loop.rate_hz). Once.
  void start(double start_s);
  [[nodiscard]] bool started() const { return !start_n_.empty(); }
  // Tick k, before plant.step(): the responses.
  void before_step(std::size_t k) noexcept;
  // Tick k, after plant.step(): the hammer's force; a record is complete at its last tick.
  void after_step(std::size_t k) noexcept;
  [[nodiscard]] std::size_t end_tick() const { return total_; }  // ticks until the last record is complete
  [[nodiscard]] bool done(std::size_t k) const { return started() && k >= total_; }
  [[nodiscard]] int records() const { return records_; }
  [[nodiscard]] double start_s() const { return start_s_; }
  // Per location, from the complete records.
  [[nodiscard]] std::vector<FrfEstimate> receptance() const;

 private:
  const config::Config& cfg_;
  sim::Plant& plant_;
  ImpactTest test_;
  std::vector<sim::Accelerometer> meas_;
  std::vector<std::size_t> start_n_;
  std::size_t record_n_{0}, total_{0}, seg_{0};
  std::vector<std::vector<double>> force_;                  // [record][sample]
  std::vector<std::vector<std::vector<double>>> response_;  // [record][location][sample]
  std::size_t hammer_{0};
  int records_{0};
  double start_s_{0.0};
};

struct DivergenceRun {
  double gain_ns_per_m{0.0};
  bool predicted_unstable{false};
  double predicted_growth_per_s{0.0};  // fs ln(spectral radius)
  bool diverged{false};
  double growth_ratio{0.0};           // command RMS at the end / just after the impact
  double measured_growth_per_s{0.0};  // slope of ln RMS after the impact, before any saturation (NaN if
                                      // the loop saturated too soon to measure it)
  bool final_window_saturated{false};
  double peak_actuator_force_n{0.0};
  double saturation_time_s{0.0};
  std::vector<double> envelope_v;  // command RMS per window
  double window_s{0.25};
};

struct MeasuredPeak {
  double freq_hz{0.0};
  double magnitude_m_per_n{0.0};
  double coherence_min{0.0};  // within +-10 % of the peak frequency
};

// Peak of |H| over [lo, hi], refined by a parabola through the three grid points around it.
[[nodiscard]] MeasuredPeak measured_peak(const FrfEstimate& e, double lo_hz, double hi_hz);

struct BenchRow {
  std::string name;
  double gain_ns_per_m{0.0};
  double impact_peak_n{0.0};
  std::optional<double> measured_improvement_pct;
  std::optional<double> predicted_improvement_pct;             // discrete loop that runs
  std::optional<double> predicted_continuous_improvement_pct;  // docs/physics.md equations
  bool saturated{false};
  double saturation_time_s{0.0};
  double peak_actuator_force_n{0.0};
  double coherence_min{0.0};
  MeasuredPeak open, closed;
  std::string kind;  // "nominal", "saturating", "sweep"
};

struct OpenLoopCheck {
  std::string name;
  double model_peak_m_per_n{0.0};
  double measured_peak_m_per_n{0.0};
  double error_db{0.0};
  double coherence_min{0.0};
};

struct BenchReport {
  std::string config;
  AnalysisResult analysis;
  std::vector<OpenLoopCheck> open_loop;
  std::vector<BenchRow> rows;
  std::vector<DivergenceRun> sweep;
  double simulated_s{0.0};
  double wall_s{0.0};
  bool ran_closed_loop{false};
  bool improvement_within_5pct{false};
  bool sweep_agrees{false};
  std::string verdict;
  std::vector<std::string> notes;
};

using Progress = std::function<void(const std::string&)>;

class Bench {
 public:
  explicit Bench(const config::Config& cfg);
  [[nodiscard]] const LoopModel& model() const { return model_; }

  [[nodiscard]] ImpactTestResult impact_test(const ImpactTest& t) const;
  [[nodiscard]] DivergenceRun divergence_run(double gain_ns_per_m, int polarity) const;
  // All runs, on `jobs` threads (0: one per core; 1: serial); the report does not depend on jobs.
  [[nodiscard]] BenchReport run(const Progress& progress = {}, std::size_t jobs = 0) const;

 private:
  // The simulated plant with the configured disturbances, and the designed controller at (K, polarity).
  [[nodiscard]] sim::Plant make_plant() const;
  [[nodiscard]] control::ControllerParams controller_params(double gain_ns_per_m, int polarity) const;
  // The report's parts (bench_report.cpp).
  [[nodiscard]] std::string test_line(int number, int tests, const ImpactTest& t, const std::string& what,
                                      const ImpactTestResult& r) const;
  [[nodiscard]] BenchRow make_row(const AnalysisResult& an, std::size_t i, const ImpactTestResult& open_r,
                                  const ImpactTestResult& closed_r, double peak_n, const std::string& kind, double k,
                                  const FrfResult* predicted, const FrfResult* predicted_c) const;
  [[nodiscard]] std::string verdict(const BenchReport& rep) const;
  // run's phases on one shared state (bench_report.cpp): the analysis with the open-loop tests, the
  // closed-loop tests with the gain sweep, then the rows and the sweep's report.
  struct RunState;
  void run_open(RunState& st) const;
  void run_closed(RunState& st) const;
  void report_closed(RunState& st) const;

  config::Config cfg_;
  LoopModel model_;
};

}  // namespace robodamp::analysis
