// The tool-workpiece relative FRF the cut sees: a 2x2 receptance matrix in the machine frame (x, y),
// summed over the structure's parts (robot + workpiece), each a modal table with cross terms or a
// location of a damping configuration, open loop or closed with its controller. Off the real-time path.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "analysis/loop_model.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "config/robot_model_config.hpp"
#include "robot/planar_chain.hpp"

namespace robodamp::milling {

using Complex = std::complex<double>;

// A resonance the frequency grids refine around.
struct Resonance {
  double freq_hz{0.0};
  double damping_ratio{0.0};
};

class Structure {
 public:
  // A location of a damping configuration: its loop model, the location, the direction (0 = x, 1 = y) and
  // the configured gain and polarity.
  struct ControllerPart {
    std::shared_ptr<const analysis::LoopModel> model;
    std::size_t location{0};
    std::size_t direction{1};
    std::optional<std::size_t> across;  // the location along the other axis (ControllerPartConfig::across_location)
    double gain_ns_per_m{0.0};
    int polarity{1};
  };
  // damped: close each controller part's loop at its configured gain and polarity. Throws
  // config::ConfigError if a controller configuration is invalid or its loop is unstable.
  Structure(const config::StructureConfig& cfg, bool damped);
  // The running loop in place of every controller part's configuration file (live stability: the cell's
  // active parameter set at its gain now, with the harmonic notches at the spindle speed): the part's
  // robot and controller come from `live`, the location and direction from the part.
  struct LiveLoop {
    std::shared_ptr<const analysis::LoopModel> model;
    double gain_ns_per_m{0.0};
    int polarity{1};
  };
  Structure(const config::StructureConfig& cfg, bool damped, const LiveLoop& live);
  // Sum of modal terms only (tests, benchmarks).
  explicit Structure(std::array<std::vector<config::ModeConfig>, 4> modes, std::string name = "modal");

  // Receptance matrix, m/N, machine frame [xx xy; yx yy].
  [[nodiscard]] Eigen::Matrix2cd frf(double f_hz) const;
  // In the cutter's frame (x = feed, y = wall normal) for a feed along feed_axis.
  [[nodiscard]] Eigen::Matrix2cd frf_cutter(double f_hz, config::Axis feed_axis) const;

  [[nodiscard]] const std::vector<Resonance>& resonances() const { return resonances_; }
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] bool damped() const { return damped_; }
  [[nodiscard]] bool has_controller() const;
  // Parts given as a robot model at a pose: the frequency domain uses the model's exact TCP receptance,
  // the time-domain cut its lowest modes (pose_modes_for_cut of them, mass-normalised, hysteretic
  // damping as viscous zeta = loss factor / 2).
  [[nodiscard]] bool has_pose_part() const { return !poses_.empty(); }
  [[nodiscard]] const std::vector<std::shared_ptr<const robot::PlanarChain>>& pose_chains() const { return poses_; }
  static constexpr std::size_t kPoseModesForCut = 8;
  // The modal tables summed per direction pair [xx, xy, yx, yy], machine frame, as given.
  [[nodiscard]] const std::array<config::FrfConfig, 4>& modal_terms() const { return modal_; }
  // Each controller part's open-loop robot FRF at its location (physical frame) and its direction
  // (0 = x, 1 = y): the structure a time-domain model needs besides the modal tables.
  struct ControllerPath {
    std::size_t direction{1};             // of the response
    std::size_t excitation_direction{1};  // of the force (a part across the plane has all four pairs)
    sim::FrfPath path;
  };
  [[nodiscard]] std::vector<ControllerPath> controller_paths() const;
  [[nodiscard]] const std::vector<ControllerPart>& controller_parts() const { return controllers_; }
  // The modal tables alone, per pair [xx, xy, yx, yy] (a Structure without the controller parts).
  [[nodiscard]] std::array<std::vector<config::ModeConfig>, 4> modal_terms_by_pair() const {
    return {modal_[0].modes, modal_[1].modes, modal_[2].modes, modal_[3].modes};
  }
  // What the controller parts were closed with, for reports.
  [[nodiscard]] const std::vector<std::string>& notes() const { return notes_; }

 private:
  std::string name_;
  bool damped_{false};
  std::array<config::FrfConfig, 4> modal_;  // xx, xy, yx, yy, all parts' modes together
  std::vector<ControllerPart> controllers_;
  std::vector<std::shared_ptr<const robot::PlanarChain>> poses_;  // TCP receptance, machine frame
  std::vector<Resonance> resonances_;
  std::vector<std::string> notes_;

  void add_pose(const std::string& part, const config::PosePartConfig& pc);
  void add_mapped_pose(const std::string& part, const config::PosePartConfig& pc, const config::RobotModelConfig& m);
  void add_controller(const std::string& part, const std::string& source, const config::ControllerPartConfig& pc,
                      std::shared_ptr<const analysis::LoopModel> model, double gain_ns_per_m, int polarity);
};

// The structure with its robot replaced by the robot a pose-scheduled cell damps (docs/pose_dynamics.md, "Tuning
// across the workspace" and "Live stability at the pose"): one part "robot", the cell's loop at the
// actuator's location along pose_schedule.axis (every location of a pose's set is the TCP), beside the
// structure's modal parts (a workpiece); its robot pose and controller parts are dropped. The loop's plant at
// the pose is the caller's (Structure's LiveLoop). location: the actuator's (actuator.location); axis: 0 = x,
// 1 = y; source: the cell's configuration file (for messages).
[[nodiscard]] config::StructureConfig robot_through_cell(const config::StructureConfig& s, int location, int axis,
                                                         const std::string& source, int across_location = 0);

}  // namespace robodamp::milling
