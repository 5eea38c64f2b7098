// Stability of the damped cut by semi-discretization of the sampled loop (docs/milling.md, "The damped cut
// by semi-discretization"). What runs is discrete at the loop period h: each controller part's loop (the
// robot's modal paths, the actuator of Eq. 3 with its delay, the sampled accelerometer, one tick of
// computation delay, the chain's sections and the harmonic notches at the speed, the gain and polarity;
// analysis::LoopModel::sampled_path) and the job's modal tables discretised exactly for a force held over
// each tick, all in the cutter's frame:
//   s[l+1] = A s[l] + B F[l],  q[l] = C s[l],
//   F[l] = K_l (q(t_l + h/2 - tau) - q(t_l + h/2)),
// K_l the directional matrix summed over the engaged teeth and slices, averaged over tick l, and tau the
// tooth period, a whole number N of ticks (the speed is moved to the nearest such one, as the time-domain
// cut does). The displacement is carried on a grid of k <= N points per tooth period, and both the current
// and the delayed displacement inside a tick are interpolated quadratically from it; each grid interval is
// solved exactly through its ticks. The monodromy matrix over one tooth period decides: stable when all its
// eigenvalues are inside the unit circle; flip when the critical one is real and negative, Hopf otherwise.
// The chatter frequency is the Floquet mode's strongest harmonic, read from the critical eigenvector's
// displacement history. Off the real-time path.
#pragma once

#include <complex>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "milling/dominant_multiplier.hpp"
#include "milling/sdm.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

struct SampledSdmSettings {
  int axial_slices{20};
  int min_grid_per_period{40};     // grid points per tooth period at least (time_domain.sdm_steps_per_period)
  double max_grid_phase_rad{0.5};  // and a grid interval at most this phase of the highest loop mode (0.25
                                   // moves the limits of active_damping_c2.yaml by 0.2 % at most, 100-700 rpm)
  static constexpr int kMinTicksPerTooth = 10;  // below, the speed grid of the loop period is too coarse
};

// Why the sampled loop's semi-discretization cannot analyse this speed (a tooth period shorter than
// kMinTicksPerTooth loop periods, or not a positive finite speed), naming the value, unit and range.
[[nodiscard]] std::optional<std::string> sampled_speed_problem(double rpm, int teeth, double loop_rate_hz);

class SampledSdm {
 public:
  // The damped structure (its controller parts closed at their gain and polarity). Throws
  // std::invalid_argument without a controller part or with parts of different loop rates.
  SampledSdm(const Structure& damped, const Cutter& cutter, const config::MaterialConfig& material,
             config::MillingMode mode, double radial_mm, config::Axis feed_axis, SampledSdmSettings settings);

  [[nodiscard]] double loop_rate_hz() const { return 1.0 / tick_s_; }
  // Ticks per tooth period at this speed (the nearest whole number).
  [[nodiscard]] int ticks_per_tooth(double rpm) const;
  // The speed the analysis runs at: the nearest whose tooth period is a whole number of ticks.
  [[nodiscard]] double stepped_rpm(double rpm) const;
  // The highest speed with at least kMinTicksPerTooth ticks per tooth period.
  [[nodiscard]] double max_rpm() const;
  [[nodiscard]] Eigen::Index states() const { return base_.a.rows(); }

  // The dominant eigenvalue of the monodromy matrix at this depth, at stepped_rpm(rpm). Throws
  // std::invalid_argument for a speed above max_rpm() or a depth that is not > 0 and finite.
  [[nodiscard]] std::complex<double> multiplier(double axial_mm, double rpm) const;
  // Critical depth (relative tolerance rel_tol) from a first guess, at stepped_rpm(rpm) (in the result).
  [[nodiscard]] SdmPoint critical(double rpm, double guess_mm, double rel_tol = 1e-3) const;

  class AtSpeed;
  // One speed's loop for the depths asked there (AccurateStability's search and its probes below it).
  [[nodiscard]] AtSpeed at(double rpm) const;

 private:
  struct System {
    Eigen::MatrixXd a, b, c;  // cutter frame: b n x 2, c 2 x n
    double highest_mode_hz{0.0};
  };
  struct Result {
    std::complex<double> mu;
    Eigen::VectorXcd history;  // the critical eigenvector's grid displacements g_{-1} .. g_{-k}
    std::vector<int> grid;     // tick index of each grid point 0..k
  };
  // A^m and A^r B of one System, made as the monodromy needs them and kept across the depths of one search
  // (one per System and thread), and the search's dominant-multiplier finder.
  struct Propagators {
    std::map<int, Eigen::MatrixXd> a_pow;  // A^m, by m
    std::vector<Eigen::MatrixXd> a_pow_b;  // A^r B, r = 0, 1, ...
    DominantMultiplier dominant;
  };
  [[nodiscard]] System system_at(double rpm) const;
  // The dominant multiplier and the grid (not the history); phi_out (optional) takes the matrix itself.
  [[nodiscard]] Result monodromy(const System& sys, Propagators& cache, double axial_mm, int ticks,
                                 Eigen::MatrixXd* phi_out = nullptr) const;
  [[nodiscard]] double chatter_hz(const Result& r, int ticks) const;

  friend class AtSpeed;
  std::vector<Structure::ControllerPart> parts_;
  std::vector<CutterModalTerm> tables_;
  Cutter cutter_;
  config::MaterialConfig material_;
  config::MillingMode mode_;
  double radial_mm_;
  config::Axis feed_axis_;
  SampledSdmSettings settings_;
  double tick_s_{0.0};
  bool per_speed_{false};  // harmonic notches: the loop depends on the speed
  System base_;
};

// One speed of a SampledSdm: the loop's system there (a LoopModel per speed with harmonic notches) and its
// propagators A^m, A^r B made once and kept across every depth asked at that speed. Each call's answer is
// bit for bit the one SampledSdm::multiplier() or critical() gives at the speed (each call starts its own
// dominant-multiplier finder, as they do). Not shared between threads; the SampledSdm must outlive it.
class SampledSdm::AtSpeed {
 public:
  [[nodiscard]] double rpm() const { return rpm_; }  // stepped
  [[nodiscard]] std::complex<double> multiplier(double axial_mm);
  [[nodiscard]] SdmPoint critical(double guess_mm, double rel_tol = 1e-3, double first_step = kBracketStep);

 private:
  friend class SampledSdm;
  AtSpeed(const SampledSdm& sdm, double rpm);
  const SampledSdm* sdm_;
  int ticks_;
  double rpm_;
  System sys_;
  Propagators cache_;
};

}  // namespace robodamp::milling
