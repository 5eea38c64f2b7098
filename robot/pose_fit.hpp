// Fitting a robot model's joints to measured TCP FRFs at one or more poses by particle swarm (the planar-robot study,
// docs/pose_dynamics.md): the joint stiffnesses (log-scaled within their bounds) and, optionally, the
// joints' damping ratios; the objective is each pose's complex FRF error over the fit band weighted by the
// measured magnitude (so the resonances dominate, as the planar-robot study weights near the peaks), averaged over the
// poses. Each restart's swarm optimum is polished by a local derivative-free search (NLopt's BOBYQA, within
// the same bounds): the swarm finds the basin, BOBYQA its bottom. Restarts with other seeds give the
// parameters' spread. Off the real-time path.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "config/robot_model_config.hpp"
#include "robot/pso.hpp"

namespace robodamp::robot {

enum class FrfDirection { kXX, kYY, kXY };

struct MeasuredFrf {
  std::string name;
  std::vector<double> joints_deg;
  std::vector<double> freq_hz;
  std::vector<std::complex<double>> receptance_m_per_n;
};

struct PoseFitSettings {
  FrfDirection direction{FrfDirection::kYY};
  double band_min_hz{10.0}, band_max_hz{30.0};  // the planar-robot study fits 10-30 Hz
  // The direct form (modes 0) costs a solve per point and searches on a coarse, thinned model: the band's
  // points thinned evenly to at most max_points_per_pose and search_elements per link. The modal form costs
  // one eigen-solve per pose and searches on the model as written over final_points_per_pose points.
  int max_points_per_pose{60};
  // Elements per link while searching (0: the model's). The links' own bending modes lie far above the fit
  // band: on the planar-robot study's preset 2 elements change its 10-30 Hz TCP FRF by 0.06 % against 6, and the search
  // runs about 20 times faster. The errors reported are the model's own.
  int search_elements{2};
  double stiffness_min_nm_per_rad{1e3}, stiffness_max_nm_per_rad{1e7};  // the planar-robot study's bounds (Eq. 21)
  // 0: the model's own receptance (its joints' hysteretic damping, every mode). N: the model's N lowest
  // modes alone, each with viscous damping of half its loss factor: the plant the emulator runs and the
  // schedule's analysis predicts with (robot::modal_tcp_frf). Fitting the form that predicts keeps the
  // difference between the two forms (a few percent of phase below each mode) out of the joints.
  int modes{0};
  bool fit_damping{true};
  double damping_min{0.002}, damping_max{0.1};
  int restarts{3};
  PsoSettings pso{};
  bool polish{true};  // each restart's swarm result refined by NLopt's BOBYQA within the bounds
  int polish_evaluations{3000};
  // The points per pose the modal form searches on and both forms report their errors on. On the measured
  // planar robot (docs/pose_dynamics.md) the modal form's joints come within 0.2 % searched this way, and
  // 1 % searched on 60 points and 2 elements (the peaks' half-power width is 2 points there).
  int final_points_per_pose{400};
};

struct PoseFitResult {
  config::RobotModelConfig fitted;  // the model with the best restart's joints
  std::vector<double> stiffness_nm_per_rad, damping_ratio;
  std::vector<double> stiffness_spread_pct;  // standard deviation / mean over the converged restarts
  int converged_restarts{0};                 // restarts ending within 0.5 points of the best's error
  std::vector<double> pose_error;            // the best fit's weighted relative RMS error per pose
  std::vector<double> restart_costs;
  int evaluations{0};
};

// Each pose's weighted relative RMS error of `model` against the data (the fit's measure, on at most
// final_points_per_pose points, for poses held out of it). Throws as fit_joints.
[[nodiscard]] std::vector<double> model_errors(const config::RobotModelConfig& model,
                                               const std::vector<MeasuredFrf>& data, const PoseFitSettings& s);

// The frequency of each pose's largest receptance in the fit band, on the measurement's own frequencies:
// of the measurement (model = nullptr) or of the model's TCP FRF there (the first mode a matched
// compensator aims at, compared like for like).
[[nodiscard]] std::vector<double> peak_hz(const config::RobotModelConfig* model, const std::vector<MeasuredFrf>& data,
                                          const PoseFitSettings& s);

// The model's receptance at a measurement's pose, on the measurement's frequencies in [f_lo_hz, f_hi_hz].
// Throws config::ConfigError for a pose outside the joints' travel.
// modes: as PoseFitSettings::modes.
[[nodiscard]] MeasuredFrf model_frf(const config::RobotModelConfig& model, const MeasuredFrf& at,
                                    FrfDirection direction, double f_lo_hz, double f_hi_hz, int modes = 0);

// Throws config::ConfigError for a pose outside the joints' travel or a measurement without points in the band.
[[nodiscard]] PoseFitResult fit_joints(const config::RobotModelConfig& model, const std::vector<MeasuredFrf>& data,
                                       const PoseFitSettings& s);

}  // namespace robodamp::robot
