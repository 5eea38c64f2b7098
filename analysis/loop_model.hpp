// The damping loop in the frequency domain (docs/physics.md §1, Eq. 8-12 with the corrected H11):
// the continuous model (actuator delay exact, the configured sensor's analog coupling) and the discrete
// loop that actually runs (the plant discretised exactly with zero-order hold at the loop rate, the
// sampled sensor, one sample of computation delay, the digital chain). Stability of the discrete loop from
// its closed-loop poles, cross-checked by a Nyquist count. Off the real-time path.
#pragma once

#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "analysis/chain_design.hpp"
#include "analysis/sampled_plant.hpp"
#include "config/config.hpp"
#include "sim_plant/plant_model.hpp"
#include "sim_plant/sensor.hpp"

namespace robodamp::analysis {

using Complex = std::complex<double>;

// Discrete state-space x[k+1] = A x + B u, y = C x + D u (SISO here).
struct DiscreteSs {
  Eigen::MatrixXd a, b, c, d;
};

// The discrete loop as a cut sees it at one location: x[k+1] = a x + b f[k], d[k] = c x, with f the
// force held over tick k at the location (N, physical frame) and d the displacement there at tick k (m).
struct SampledPath {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  Eigen::RowVectorXd c;
};
struct SampledPaths {
  Eigen::MatrixXd a, b, c;
};

// The loop is what it computes, in two parts: the sampled plant (analysis/sampled_plant.hpp: the plant, its
// sensor and its discretisation at the loop rate, shared) and the controller's side (the designed chain, the
// harmonic notches at a spindle speed, the unit open loop they close).
class LoopModel {
 public:
  // spindle_rpm: with controller.harmonic_notch, the notches at that speed (fully faded in) join the
  // chain: the discrete loop runs them, the continuous model takes their digital response.
  explicit LoopModel(const config::Config& cfg, std::optional<double> spindle_rpm = std::nullopt);
  // The same loop with the notches at spindle_rpm: this model's sampled plant, the chain designed again.
  [[nodiscard]] LoopModel at_speed(double spindle_rpm) const;
  // cfg's controller (its chain, gain and polarity) on this model's sampled plant, with its sweeps: cfg is this
  // model's configuration but for its controller section (a tune's candidate). Throws std::invalid_argument
  // where its loop rate is not this plant's.
  [[nodiscard]] LoopModel with_controller(const config::Config& cfg) const;
  // The plant's responses on a grid, computed once for every loop on this sampled plant (SampledPlant::sweep).
  [[nodiscard]] std::shared_ptr<const std::vector<PlantResponse>> plant_sweep(const LogGrid& grid) const {
    return s_->sweep(grid);
  }

  [[nodiscard]] const sim::PlantModel& plant() const { return s_->plant; }
  [[nodiscard]] const analysis::ChainDesign& chain() const { return chain_; }
  [[nodiscard]] const config::Config& config() const { return cfg_; }
  [[nodiscard]] std::size_t sensor_location() const { return s_->sensor; }
  [[nodiscard]] std::size_t actuator_location() const { return s_->plant.actuator.location; }
  [[nodiscard]] double loop_rate_hz() const { return cfg_.loop.rate_hz; }
  // The harmonic notches in the model (none without a spindle speed) and their response.
  [[nodiscard]] std::size_t notch_count() const { return notches_.count; }
  [[nodiscard]] Complex notch_response(double f_hz) const;
  [[nodiscard]] std::optional<double> spindle_rpm() const { return spindle_rpm_; }

  // Force per displacement at the sensor location that the controller feeds back (F_act = Q x_s), for
  // gain K and polarity; continuous: Q = pol K / T * filters * H_act e^{-s t_a} * S(s) * s^2.
  [[nodiscard]] Complex feedback_continuous(double f_hz, double gain_ns_per_m, int polarity) const;
  // Return-difference loop gain L (closed loop = 1 / (1 + L)), continuous and discrete.
  [[nodiscard]] Complex loop_continuous(double f_hz, double gain_ns_per_m, int polarity) const;
  [[nodiscard]] Complex loop_discrete(double f_hz, double gain_ns_per_m, int polarity) const;
  [[nodiscard]] Complex loop_discrete(const PlantResponse& p, Complex chain_filters, double gain_ns_per_m,
                                      int polarity) const;

  // Receptance from force at h to displacement at g (physical frame), open and closed loop.
  [[nodiscard]] Complex open_continuous(std::size_t g, std::size_t h, double f_hz) const;
  [[nodiscard]] Complex closed_continuous(std::size_t g, std::size_t h, double f_hz, double gain_ns_per_m,
                                          int polarity) const;
  // The continuous structure under the sampled controller, the view chatter sees at any frequency: the
  // digital chain at z = e^{sT}, one period of computation delay and the zero-order hold in place of the
  // analog chain (aliasing neglected; equals closed_discrete well below Nyquist).
  [[nodiscard]] Complex feedback_sampled(double f_hz, double gain_ns_per_m, int polarity) const;
  [[nodiscard]] Complex closed_sampled(std::size_t g, std::size_t h, double f_hz, double gain_ns_per_m,
                                       int polarity) const;
  // Discrete: sampled accelerance / (-w^2), as an impact test at the loop rate measures it.
  [[nodiscard]] PlantResponse plant_response(double f_hz) const;
  [[nodiscard]] Complex chain_filters_digital(double f_hz) const { return chain_.filters_digital(f_hz); }
  [[nodiscard]] Complex open_discrete(const PlantResponse& p, std::size_t g, std::size_t h) const;
  [[nodiscard]] Complex closed_discrete(const PlantResponse& p, Complex chain_filters, std::size_t g, std::size_t h,
                                        double gain_ns_per_m, int polarity) const;

  // Volts the controller commands per newton of held force at location h, the loop closed (discrete loop
  // that runs, before any limit): V = q A_sh / (1 - q A_sv), q the chain's volts per sampled m/s^2.
  [[nodiscard]] Complex command_per_force(const PlantResponse& p, Complex chain_filters, std::size_t h,
                                          double gain_ns_per_m, int polarity) const;
  // The same in two steps, for several locations at one frequency: q, the volts the controller commands per
  // m/s^2 of sampled acceleration (with its computation delay), then the command per newton at h.
  [[nodiscard]] Complex feedback_discrete(const PlantResponse& p, Complex chain_filters, double gain_ns_per_m,
                                          int polarity) const;
  [[nodiscard]] Complex command_per_force(const PlantResponse& p, Complex feedback_discrete, std::size_t h) const;

  // Volts the controller commands per m/s^2 of noise added to the sensor's reading (after its analog
  // response), the loop closed: V = q' / (1 - q A_sv), q' = q without the sensor's response.
  [[nodiscard]] Complex command_per_sensor_noise(const PlantResponse& p, Complex chain_filters, double gain_ns_per_m,
                                                 int polarity) const;
  // Volts per m/s^2 of acceleration at the sensor that an outside force causes with control off.
  [[nodiscard]] Complex command_per_open_accel(const PlantResponse& p, Complex chain_filters, double gain_ns_per_m,
                                               int polarity) const;
  [[nodiscard]] const sim::Accelerometer& sensor_model() const { return s_->sensor_model; }

  // The loop that runs, closed at gain K and polarity, from a force held over each tick at `location` to
  // the displacement there (milling/sampled_sdm.hpp: the damped cut's semi-discretization).
  [[nodiscard]] SampledPath sampled_path(std::size_t location, double gain_ns_per_m, int polarity) const;
  // The same from forces held at several locations to the displacements there (b: a column per location,
  // c: a row): a controller part that acts on the robot in both directions of the plane.
  [[nodiscard]] SampledPaths sampled_paths(const std::vector<std::size_t>& locations, double gain_ns_per_m,
                                           int polarity) const;

  // Closed-loop state matrix of the discrete loop and its eigenvalues.
  [[nodiscard]] Eigen::MatrixXd closed_loop_matrix(double gain_ns_per_m, int polarity) const;
  [[nodiscard]] Eigen::VectorXcd closed_loop_poles(double gain_ns_per_m, int polarity) const;
  [[nodiscard]] double spectral_radius(double gain_ns_per_m, int polarity) const;
  [[nodiscard]] bool stable(double gain_ns_per_m, int polarity) const {
    return spectral_radius(gain_ns_per_m, polarity) < 1.0;
  }
  // Controller output -> controller output at K = 1, polarity +1: the closed loop is a + polarity K b c.
  [[nodiscard]] const DiscreteSs& open_loop_unit() const { return open_loop_unit_; }
  // Net clockwise encirclements of -1 by L(e^{jwT}) over the whole unit circle (0 for a stable loop,
  // all open-loop poles being inside the unit circle).
  [[nodiscard]] int nyquist_encirclements(double gain_ns_per_m, int polarity) const;

 private:
  LoopModel(const config::Config& cfg, std::shared_ptr<const SampledPlant> sampled, std::optional<double> spindle_rpm);
  config::Config cfg_;
  std::shared_ptr<const SampledPlant> s_;
  filters::SosCoefficients notches_{};
  std::optional<double> spindle_rpm_;
  analysis::ChainDesign chain_;
  // Closed-loop receptance g <- h for a feedback force q per displacement at the sensor.
  [[nodiscard]] Complex closed_with_feedback(std::size_t g, std::size_t h, double f_hz, Complex q) const;
  DiscreteSs open_loop_unit_;  // controller output -> controller output at K = 1, polarity +1 (no gain yet)
  // The same, with the last held force at force_at as one more plant state (sampled_path).
  [[nodiscard]] DiscreteSs open_loop(const std::vector<std::size_t>& forces_at) const;
};

// --- Results -------------------------------------------------------------------------------------

struct FrfResult {
  std::string name;  // as configured (e.g. H22yy)
  std::size_t response{0}, excitation{0};
  double open_peak_m_per_n{0.0};
  double closed_peak_m_per_n{0.0};
  double open_peak_freq_hz{0.0};
  double peak_freq_hz{0.0};  // of the closed-loop peak
  double improvement_pct{0.0};
};

struct ModePhase {
  double freq_hz{0.0};
  double feedback_phase_deg{0.0};  // phase of -F_act / v at the sensor: damping within (-90, 90)
  bool damps{false};
};

struct Margins {
  std::optional<double> gain_margin_db;    // 20 log10(K_max / K); none if stable up to the gain limit
  std::optional<double> phase_margin_deg;  // smallest angular distance of L from -1 at a gain crossover
  std::optional<double> phase_crossover_hz;
  std::optional<double> gain_crossover_hz;
  std::optional<double> delay_margin_ms;  // smallest extra pure delay that turns L onto -1 at a crossover
  // The lowest gain at which the swept curve meets -1: its crossings of the negative real axis, and the sweep's
  // ends where L is on the negative side (a bound there). max_stable_gain starts its scan below it.
  std::optional<double> crossing_gain_ns_per_m;
};

struct AnalysisResult {
  double gain_ns_per_m{0.0};
  int polarity{1};
  bool stable{false};
  double spectral_radius{0.0};
  int nyquist_encirclements{0};
  bool stable_continuous{false};
  std::optional<double> max_stable_gain_ns_per_m;  // none = stable up to kMaxGainNsPerM
  Margins margins;
  int recommended_polarity{1};
  std::string polarity_reason;
  std::vector<ModePhase> modes;
  std::vector<FrfResult> frfs_continuous;
  std::vector<FrfResult> frfs_discrete;
  // The command on a quiet cell (analysis/quiet_command.hpp), stable loops only.
  double quiet_command_rms_v{0.0};
  double quiet_command_peak_hz{0.0};
  std::vector<std::string> notes;
};

// Peak of |H| over [lo, hi] on a grid refined by golden-section search around each local maximum.
struct Peak {
  double freq_hz{0.0};
  double magnitude{0.0};
};
// grid_hz ascending with values[i] = magnitude(grid_hz[i]); refine() evaluates between grid points.
[[nodiscard]] Peak find_peak(const std::vector<double>& grid_hz, const std::vector<double>& values,
                             const std::function<double(double)>& refine);
[[nodiscard]] std::vector<double> linear_grid(double lo_hz, double hi_hz, double step_hz);

// Net counter-clockwise turns of arg(fn(f)) as f goes lo -> hi, by adaptive subdivision.
[[nodiscard]] double turns(const std::function<Complex(double)>& fn, double lo_hz, double hi_hz);
// The same over an ascending grid, subdividing between its points (dense where fn varies fast).
[[nodiscard]] double turns(const std::function<Complex(double)>& fn, const std::vector<double>& grid_hz);

// Improvement and the dominant closed-loop pole across K (the root-locus view of the gain).
struct SweepPoint {
  double gain_ns_per_m{0.0};
  double spectral_radius{0.0};
  double least_damping_ratio{0.0};  // of the closed-loop poles below Nyquist/2, from s = fs ln z
  double least_damped_hz{0.0};
  std::vector<double> improvement_pct;  // per configured FRF (discrete loop)
};
[[nodiscard]] std::vector<SweepPoint> gain_sweep(const LoopModel& m, int polarity, const std::vector<double>& gains);

// Smallest K > 0 at which the discrete loop becomes unstable (log scan, then bisection to 1e-6). With the
// margins' crossing gain the scan starts at its last step below 0.8 x that gain, once the poles there are
// checked stable (else from the start): the same answer, from a few steps instead of some 60.
[[nodiscard]] std::optional<double> max_stable_gain(const LoopModel& m, int polarity,
                                                    std::optional<double> crossing_gain_ns_per_m = std::nullopt);
[[nodiscard]] Margins margins(const LoopModel& m, double gain_ns_per_m, int polarity, std::optional<double> max_gain);
// 20 log10(K_max / K), as Margins::gain_margin_db holds it.
[[nodiscard]] inline double gain_margin_db(double max_gain_ns_per_m, double gain_ns_per_m) {
  return 20.0 * std::log10(max_gain_ns_per_m / gain_ns_per_m);
}
[[nodiscard]] std::vector<FrfResult> improvements(const LoopModel& m, double gain_ns_per_m, int polarity,
                                                  bool discrete);
// Phase of the feedback force against the velocity at each mode of the loop's own FRF (continuous loop).
[[nodiscard]] std::vector<ModePhase> mode_phases(const LoopModel& m, double gain_ns_per_m, int polarity);
[[nodiscard]] AnalysisResult analyse(const LoopModel& m);
[[nodiscard]] AnalysisResult analyse(const LoopModel& m, double gain_ns_per_m, int polarity);

}  // namespace robodamp::analysis
