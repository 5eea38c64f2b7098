// The robot's modes at any pose from modes measured at a few (docs/pose_dynamics.md, "Modes between measured
// poses"). The robot model (fitted or not) is the prior: at each measured pose its modes along the measured
// axis are matched to the measured ones. Each measured mode's frequency, damping ratio and participation along
// the axis (w^2 / k) is interpolated over joint space by Gaussian-process regression (ordinary kriging: a
// constant mean, a squared-exponential kernel over the joint angles in rad, averaged over a grid of length
// scales weighted by their restricted marginal likelihood), in one of two forms: against the model's mode (the
// log ratio measured / model, the participation's difference), or as the measured values themselves, whichever
// predicts each measured pose better from the others (leave-one-out). A model right in form carries the shape
// between the poses; one wrong in form (its damping varying where the measured is flat, its participation
// through zero where the measured peaks) is left out of the quantities it predicts worse. At a measured pose the
// mapped modes are the measured ones (to the measurement's noise); far from every measured pose the regression
// tends to its mean and its uncertainty to the values' scatter, so the spread grows away from the measurements.
// Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "config/robot_model_config.hpp"

namespace robodamp::robot {

// One of the model's modes as it moves the TCP along an axis (modal-stiffness form, lowest first): the
// modes that do not move the TCP along the axis are left out.
struct AxisMode {
  double freq_hz{0.0};
  double damping_ratio{0.0};      // half the joints' loss factor (modal_damping_ratio)
  double stiffness_n_per_m{0.0};  // w^2 / phi_axis^2
  Eigen::Vector2d tcp_shape{0.0, 0.0};
};
// Throws config::ConfigError (a pose outside the travel) or std::invalid_argument (a non-physical model).
[[nodiscard]] std::vector<AxisMode> axis_modes(const config::RobotModelConfig& model,
                                               const std::vector<double>& joints_deg, int axis, int count);

// One mode at a pose, mapped. A track is one mode over the measured poses: the measured modes matched to the
// same model mode (the nearest within 25 %), or those the model has no match for, by their rank among the
// unmatched at each pose. A matched track has that model mode as its prior (model_index >= 0): each quantity
// is interpolated against it or as its own values (TrackForm); an unmatched one from its own values
// (model_index -1). The model's modes no
// track follows and above every track stay as the model has them (measured_poses 0, no spread); below, where
// the measurements would have seen them, they are not there.
// sigma_*: one standard deviation of the log value (x 100: about a percentage); the stiffness's from its
// participation's, relative to the mapped one.
struct ModeCorrection {
  double freq_hz{0.0}, damping_ratio{0.0}, stiffness_n_per_m{0.0};   // the mapped mode
  double freq_scale{1.0}, damping_scale{1.0}, stiffness_scale{1.0};  // against the model's mode model_index
  double freq_sigma{0.0}, damping_sigma{0.0}, stiffness_sigma{0.0};
  int measured_poses{0};  // the track's poses (0: the model's mode as it is)
  int model_index{-1};    // the model's mode (in axis_modes' order) it corrects; -1: the measurements' own
  [[nodiscard]] bool measured_only() const { return model_index < 0; }
};

// Which model mode each measured mode at a measured pose lies nearest (-1: none within 25 %).
struct PoseMatch {
  std::string pose;
  std::vector<int> model_of_measured;
};

// How one quantity of a track is interpolated: against the model's mode (the log ratio, or the participation's
// difference) or as the track's own values, whichever predicts the measured poses better when each is left out
// in turn (the root mean square of those errors, in the quantity's regression units: log for the frequency and
// the damping, 1/kg for the participation w^2 / k; 0 where not computed).
struct QuantityForm {
  bool own{true};
  double own_rms{0.0}, model_rms{0.0};
};
struct TrackForm {
  int model_index{-1};  // the model's mode the track follows (-1: none)
  int measured_poses{0};
  double min_hz{0.0}, max_hz{0.0};  // its measured frequencies
  QuantityForm freq, damping, stiffness;
};

class ModalMap {
 public:
  // model.measured_modes must be set; its axis must be `axis`. count: the model's modes (pose_schedule.modes).
  // Throws std::invalid_argument naming the reason (another axis, no measured pose).
  ModalMap(const config::RobotModelConfig& model, int axis, int count);

  // The mapped modes at a pose, the `count` lowest of: every track (kept when measured at half the poses at
  // least) and the model's modes no track follows. prior: axis_modes(model, joints_deg, axis, count).
  [[nodiscard]] std::vector<ModeCorrection> at(const std::vector<double>& joints_deg,
                                               const std::vector<AxisMode>& prior) const;
  [[nodiscard]] const std::vector<PoseMatch>& matches() const { return matches_; }
  // Each track's forms, lowest measured mode first.
  [[nodiscard]] std::vector<TrackForm> forms() const;
  // The distance in joint space (deg) from a pose to the nearest measured pose.
  [[nodiscard]] double nearest_measured_deg(const std::vector<double>& joints_deg) const;

  // One quantity of one mode over the measured poses (public for the tests).
  class Field {
   public:
    Field() = default;
    // x: the poses (rad), y: the log ratios there, noise: the measurement's standard deviation of y. Far
    // from the data the spread is at least the root mean square of y (a ratio: the model's whole error), or
    // with about_mean, of y about its mean (a value of its own).
    Field(std::vector<Eigen::VectorXd> x, std::vector<double> y, double noise, bool about_mean = false);
    [[nodiscard]] double mean(const Eigen::VectorXd& x) const;
    [[nodiscard]] double sigma(const Eigen::VectorXd& x) const { return estimate(x).sigma; }
    struct Estimate {
      double mean{0.0}, sigma{0.0};
    };
    [[nodiscard]] Estimate estimate(const Eigen::VectorXd& x) const;  // mean and sigma at once
    [[nodiscard]] bool empty() const { return x_.empty(); }
    [[nodiscard]] std::size_t points() const { return x_.size(); }

   private:
    // The regression at one length scale, its weight its share of the likelihood.
    struct Scale {
      double length_rad{0.5}, weight{0.0}, signal_var{0.0}, mu{0.0}, ones_r_ones{1.0};
      Eigen::LDLT<Eigen::MatrixXd> r;
      Eigen::VectorXd alpha, r_ones;
    };
    [[nodiscard]] Eigen::VectorXd kernel_column(const Eigen::VectorXd& x, double length_rad) const;
    std::vector<Eigen::VectorXd> x_;
    std::vector<Scale> scales_;
  };

 private:
  struct Track {
    Field freq, damping, stiffness;
    TrackForm form;
    int model_index{-1};
  };
  std::vector<Track> tracks_;
  int count_{0};
  std::vector<PoseMatch> matches_;
  std::vector<std::vector<double>> measured_deg_;
};

}  // namespace robodamp::robot
