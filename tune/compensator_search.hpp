// Compensator synthesis (robodamp tune; docs/tuning.md): the compensator block of a configuration's chain
// replaced by a rational transfer function of bounded order, and its shape and the gain K searched with
// NLopt (a seeded global search, then a local polish) against the analysis of the discrete loop that runs.
//
// The shape, minimum phase and stable by construction (every coefficient positive):
//   C(s) = g (s^2/wz^2 + 2 zeta_z s/wz + 1) / (s^2/wp^2 + 2 zeta_p s/wp + 1) * (s/wa + 1) / (s/wb + 1)
// with g making |C| = 1 at the match frequency (the dominant mode).
// Objective: with a milling job, the smallest damped limiting depth by the sampled loop's semi-discretization
// (milling/sampled_sdm.hpp) at the speeds where it can be lowest (the job's speed, the damped zero-order
// lobes' lowest minima, the open loop's SDM minima); without one, the smallest peak of the closed-loop
// receptances over the analysis band. Constraints: stable, gain
// margin, phase margin and delay margin at least the settings'; every mode of the loop inside the damping
// window (the feedback force within 90 deg of -velocity); the command for an impact within the
// actuator's force, voltage and slew limits; with a job no lobe floor lower than the open loop's (between
// two neighbouring peaks of the open-loop lobes, the smallest damped limit at least the smallest open-loop
// limit there). Over several plants (mountings, shifted modes) the worst case. Off the real-time path.
#pragma once

#include <algorithm>
#include <complex>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/mode_improvement.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/lobes.hpp"

namespace robodamp::analysis {
class LoopModel;
}  // namespace robodamp::analysis

namespace robodamp::tune {

struct Candidate {
  double gain_ns_per_m{2000.0};
  double fz_hz{10.0}, zeta_z{0.5};  // the second-order zero pair
  double fp_hz{10.0}, zeta_p{0.5};  // the second-order pole pair
  double fa_hz{10.0}, fb_hz{10.0};  // the first-order zero and pole
  int polarity{1};
};

// The candidate as the chain's compensator block (kind compensator, model rational, pre-warped at the
// configuration's match frequency), scaled to unity gain at unity_hz: K is then the velocity feedback
// gain at that frequency whatever the shape.
[[nodiscard]] config::BlockConfig compensator_block(const Candidate& c, const config::BlockConfig& replaced,
                                                    double unity_hz);
// The search's range of K, N s/m, and of the shape: the pairs' and the first-order terms' frequencies, Hz,
// and the pairs' damping ratios.
inline constexpr double kGainMinNsPerM = 100.0, kGainMaxNsPerM = 20000.0;
inline constexpr double kPairMinHz = 0.3, kPairMaxHz = 80.0, kFirstOrderMinHz = 0.3, kFirstOrderMaxHz = 200.0;
inline constexpr double kZetaMin = 0.05, kZetaMax = 1.5;
// The candidate's compensator at f_hz, continuous and before its scaling to unity at the match frequency.
[[nodiscard]] std::complex<double> compensator_response(const Candidate& c, double f_hz);
// Its largest gain from 0.1 Hz to nyquist_hz over its gain at match_hz: what TuneSettings::compensator_gain_max
// bounds (Evaluation::compensator_gain_ratio).
[[nodiscard]] double compensator_gain_ratio(const Candidate& c, double match_hz, double nyquist_hz);

// The same controller (compensator and gain) with K stated at to_hz instead of from_hz: a set tuned with one
// match frequency, as a start for a configuration with another; K kept inside the search's range.
[[nodiscard]] Candidate restated(const Candidate& c, double from_hz, double to_hz);
// The candidate a configuration runs: its chain's rational compensator of the search's form (a cubic over a
// cubic: one pair of zeros or of real roots and one real root each, in the left half plane), its gain and
// polarity; what `robodamp tune --start` resumes from. Nothing when the chain's compensator is not of that form
// (C1, C2, C3, or another order).
[[nodiscard]] std::optional<Candidate> candidate_of(const config::Config& cfg);
// The match frequency (controller.match_freq_hz, else the dominant robot mode).
[[nodiscard]] double unity_gain_hz(const config::Config& cfg);
// The configuration with the candidate's compensator, gain and polarity. Throws config::ConfigError when
// the chain has no compensator block to replace.
[[nodiscard]] config::Config with_candidate(const config::Config& base, const Candidate& c);

struct TuneSettings {
  double gain_margin_min_db{6.0};
  double phase_margin_min_deg{45.0};
  double delay_margin_min_ms{0.5};
  // With a job: the limiting depth at the job's spindle speed (cut.spindle_rpm) at least this, mm (0 = no
  // such constraint). For the trade-off between the minimum and one speed's lobe.
  double depth_at_speed_min_mm{0.0};
  // The actuator's limits (force, coil voltage, slew) not reached, by the command the discrete loop predicts
  // for an impact at every location (analysis/impact_command.hpp). Unset: the configuration's bench
  // nominal impact (bench.impact_peak_n, bench.impact_duration_ms); a peak of 0 drops the constraint.
  std::optional<double> impact_peak_n;
  std::optional<double> impact_duration_ms;
  int global_evaluations{240};  // per polarity
  int local_evaluations{120};
  int seed{1};
  int restarts{1};  // whole searches with seeds seed, seed + 1, ...; the best kept (the search is not global)
  // No robot mode's receptance peak worse than open loop (analysis/mode_improvement.hpp) on any plant: a
  // constraint when set (tune --no-worse-mode; off by default, the presets' tunings predate it).
  bool no_worse_mode{false};
  // How much worse than open loop a mode's peak may get before no_worse_mode counts it (%): 0 for tune;
  // the pose tune allows 1 % (a mode the loop cannot reach moves by a fraction of that either way).
  double worse_mode_tolerance_pct{0.0};
  // The modes no_worse_mode and worst_mode_objective count: those with a frequency in this band (Hz; the
  // pose tune's pose_schedule damping band). Default: every mode.
  double mode_band_min_hz{0.0}, mode_band_max_hz{1e9};
  // Every mode of the loop inside the damping window (a constraint by default). The pose tune drops it for
  // no_worse_mode, which judges its consequence where it matters: a mode the actuator barely moves along its
  // axis may sit outside the window and lose a fraction of a percent.
  bool damping_window{true};
  // Without a job, the objective: the smallest improvement of any robot mode's peak (max-min over the
  // modes and the plants; the pose tune's) instead of the largest closed-loop peak.
  bool worst_mode_objective{false};
  // The compensator's gain over all frequencies (0.1 Hz to Nyquist) at most this many times its gain at the
  // match frequency (0: no such constraint; the pose tune's 10): a set that shapes the phase without lifting
  // the drift, the drive vibration or the noise far from the modes it damps.
  double compensator_gain_max{0.0};
};

struct Evaluation {
  Candidate candidate;
  bool stable{false};
  double gain_margin_db{0.0}, phase_margin_deg{0.0}, delay_margin_ms{0.0};
  double k_max_ns_per_m{0.0};
  double worst_mode_phase_deg{0.0};    // the largest |phase of -F / v| over the loop's modes (< 90: all damped)
  double compensator_gain_ratio{0.0};  // with compensator_gain_max: the largest |C| over |C(match)|
  // With no_worse_mode: the smallest improvement of a mode's peak; NaN when not asked for.
  double worst_mode_improvement_pct{std::numeric_limits<double>::quiet_NaN()};
  double min_depth_mm{0.0};       // with a job: the damped lobes' minimum (zero-order: it steers the search;
                                  // tune/verification.hpp gives the verified one)
  double depth_at_speed_mm{0.0};  // with a job: the damped limit at the job's spindle speed (sampled-loop SDM)
  double accurate_min_mm{0.0};    // with a job: the objective, the smallest sampled-loop SDM limit over the job's
  double accurate_min_rpm{0.0};   // speed, the damped zero-order lobes' lowest minima and the open SDM minima
  double open_minima_ratio{0.0};  // with a job: min over the open loop's SDM minima of damped / open (accurate)
  double floor_ratio{0.0};        // with a job: min over the open lobes' intervals of damped / open floor
  std::vector<double> floors_mm;  // with a job: the damped floor in each of the open lobes' intervals
  std::vector<double> at_open_minima_mm;  // with a job: the damped limit at each open-loop floor's speed
  double peak_m_per_n{0.0};               // without a job: the largest closed-loop peak
  double peak_coil_force_n{0.0};          // at the impact: T |V|, the largest coil voltage, the largest slew
  double peak_command_v{0.0};
  double peak_slew_v_per_s{0.0};
  double actuator_use{0.0};  // the largest of those over its limit (1 = at a limit; 0 without the check)
  double quiet_command_rms_v{
      0.0};               // the command on a quiet cell (sensor noise, drive vibration): analysis/quiet_command.hpp
  double objective{0.0};  // larger is better (depth in mm, or -log10 of the peak)
  double violation{0.0};  // 0 when every constraint holds
  std::string binding;    // the constraint violated most (empty when feasible)
  std::string plant;      // the plant this describes (with several, the worst case's)
  std::vector<Evaluation> per_plant;  // with several plants: each plant's own evaluation
  [[nodiscard]] bool feasible() const { return violation <= 0.0; }
};

struct TuneResult {
  Evaluation best;
  std::vector<Evaluation> history;  // every evaluation, in order
};

using analysis::ModeImprovement;  // the receptance peak near one robot mode, open and closed loop

// One candidate, evaluated on one plant (a configuration: mounting, robot modes, chain). Never throws for
// a bad candidate (it is infeasible with the reason).
class Evaluator {
 public:
  // name: how reports call this plant (default: the configuration's file).
  Evaluator(const config::Config& base, std::optional<config::MillingConfig> job, const TuneSettings& s,
            std::string name = {});
  ~Evaluator();
  Evaluator(Evaluator&&) noexcept;
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;
  Evaluator& operator=(Evaluator&&) = delete;
  // constraints_only: stop after the cheap constraints (stability, margins, the damping window, the
  // actuator's limits), objective 0; the search uses it to skip the lobes of a candidate already infeasible.
  [[nodiscard]] Evaluation operator()(const Candidate& c, bool constraints_only = false) const;
  // The rest of a candidate's evaluation after its constraints: finish((*this)(c, true)) equals (*this)(c),
  // without checking the loop's constraints a second time.
  [[nodiscard]] Evaluation finish(Evaluation checked) const;
  // Any configuration at its own gain and polarity (C1, C2, C3 for the report).
  [[nodiscard]] Evaluation assess(const config::Config& cfg, bool constraints_only = false) const;
  // The open loop's lobes, for reports: the minimum and the floors between neighbouring peaks.
  [[nodiscard]] double open_min_depth_mm() const { return open_min_mm_; }
  // With a job: the open loop's smallest limit by the accurate method at its lowest SDM minima.
  [[nodiscard]] double open_accurate_min_mm() const {
    return open_sdm_min_mm_.empty() ? open_min_mm_
                                    : *std::min_element(open_sdm_min_mm_.begin(), open_sdm_min_mm_.end());
  }
  [[nodiscard]] const std::vector<std::pair<double, double>>& open_intervals_rpm() const { return intervals_; }
  [[nodiscard]] const std::vector<double>& open_floors_mm() const { return floors_mm_; }
  [[nodiscard]] const std::vector<double>& open_floor_rpm() const { return floor_rpm_; }
  [[nodiscard]] const config::Config& base() const { return base_; }
  // For reports: the open loop's lobes (SDM), a configuration's damped lobes (the job's structure closed
  // through its loop, the sampled loop's SDM; both on the job's time_domain.sdm_points speeds), and its
  // improvement at each mode of the first configured FRF (the TCP's, discrete loop).
  [[nodiscard]] const std::vector<std::pair<double, double>>& open_curve_mm() const { return open_curve_; }
  [[nodiscard]] std::vector<std::pair<double, double>> damped_curve_mm(const config::Config& cfg) const;
  [[nodiscard]] std::vector<ModeImprovement> mode_improvements(const config::Config& cfg) const;
  [[nodiscard]] const std::string& name() const { return name_; }
  // A plant that only constrains the search (stability, margins, the damping window, the actuator's limits):
  // robustness to it at a fraction of the cost; its lobes are never computed.
  void set_constraints_only(bool on) { constraints_only_ = on; }
  [[nodiscard]] bool constraints_only() const { return constraints_only_; }

 private:
  struct Impact;
  // assess's last step: the objective (with a job, score_on_job; without, the closed-loop peak).
  void score(Evaluation& e, const std::shared_ptr<const analysis::LoopModel>& m) const;
  // With a job: the damped depths, the objective and the floors' constraints.
  void score_on_job(Evaluation& e, const std::shared_ptr<const analysis::LoopModel>& m) const;
  [[nodiscard]] Evaluation assess_model(const std::shared_ptr<const analysis::LoopModel>& m,
                                        bool constraints_only) const;
  // A candidate's loop on the base's sampled plant (and its shared sweeps).
  [[nodiscard]] std::shared_ptr<const analysis::LoopModel> candidate_model(const Candidate& c) const {
    return std::make_shared<const analysis::LoopModel>(base_model_->with_controller(with_candidate(base_, c)));
  }
  config::Config base_;
  std::shared_ptr<const analysis::LoopModel> base_model_;  // the base's loop: its sampled plant for every candidate
  std::string name_;
  std::unique_ptr<Impact> impact_;  // the actuator-limit check's precomputed plant (one thread at a time)
  std::optional<config::MillingConfig> job_;
  std::optional<milling::ChatterProcess> process_;  // with a job: what its cut contributes
  TuneSettings s_;
  double open_min_mm_{0.0};
  std::vector<std::pair<double, double>> intervals_;        // between neighbouring open-loop lobe peaks
  std::vector<double> floors_mm_;                           // the open loop's smallest limit in each
  std::vector<double> floor_rpm_;                           // and the speed where it is
  std::vector<std::pair<double, double>> open_curve_;       // rpm, mm (inf where no lobe reaches)
  std::vector<double> open_sdm_min_rpm_, open_sdm_min_mm_;  // the open loop's lowest SDM minima
  bool constraints_only_{false};
};

// The search's order: feasible before infeasible; then the larger objective, or the smaller violation.
[[nodiscard]] bool better(const Evaluation& a, const Evaluation& b);

// Several plants at once (both mountings, shifted modes): the candidate evaluated on each and the worst case
// kept: the smallest objective and margins, the largest violation, named with its plant. With
// skip_infeasible_objective, a candidate that already violates a cheap constraint on some plant is not
// given its lobes (objective 0): the search's order of infeasible candidates is by violation alone anyway.
[[nodiscard]] Evaluation evaluate_worst(const std::vector<const Evaluator*>& plants, const Candidate& c,
                                        bool skip_infeasible_objective = false);

// The configuration with every robot mode's natural frequency times `factor` at the same modal mass
// (residues / factor, modal stiffnesses x factor^2): for robustness to modal frequency shifts.
[[nodiscard]] config::Config with_shifted_modes(const config::Config& base, double factor);

// Throws config::ConfigError when the configuration cannot be tuned (no compensator block, a job without
// a damping location). The result may be infeasible: the caller reports the binding constraint.
[[nodiscard]] TuneResult tune(const config::Config& base, const std::optional<config::MillingConfig>& job,
                              const TuneSettings& s, const std::function<void(const std::string&)>& progress = {});
// With evaluators the caller keeps (their open-loop lobes computed once, for the report too). Several
// plants make the robust tune: the worst case over the plants optimised; the search starts from the first's C1 shape.
[[nodiscard]] TuneResult tune(const std::vector<const Evaluator*>& plants, const TuneSettings& s,
                              const std::function<void(const std::string&)>& progress = {});

// The search (seeded global, then the polish) at the start's polarity over the plants, from `start`; the
// start's own evaluation first (the result is never worse than the start).
[[nodiscard]] TuneResult tune_from(const std::vector<const Evaluator*>& plants, const Candidate& start,
                                   const TuneSettings& s, const std::function<void(const std::string&)>& progress = {});

}  // namespace robodamp::tune
