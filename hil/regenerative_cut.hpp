// The HIL emulator's regenerative cut (docs/milling.md, "The cut across processes"): the time-domain cut
// of milling/ (surface memory per slice and angle, helix, runout, loss of contact, the job's force model)
// stepped against the emulated robot, whose actuator a separate robodamp run drives through the CAN and
// Modbus path. The cutting force acts on the plant at the job's controller part (its location and
// direction); the job's modal tables (the tool, the workpiece) are stepped beside it, as the in-process
// damped cut (milling/damped_dynamics.hpp) does with the Controller in the same loop. The speed is made a
// whole number of loop periods per tooth, as there. The chatter detector classifies the record as the
// in-process cut's, so the two processes' verdicts compare. Built before the run (allocates); the
// per-step calls do not.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/chatter.hpp"
#include "milling/cut_process.hpp"
#include "milling/cut_simulation.hpp"
#include "milling/tool_dynamics.hpp"
#include "sim_plant/excitation.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::hil {

struct RegenerativeCutOptions {
  std::string job_path;
  std::optional<double> rpm, axial_mm;  // default: the job's
  std::optional<int> revolutions;       // default: the job's time_domain.revolutions, at least 300
  // Plant time the tool enters the cut, s; negative: hil.settle_s + controller.gain_ramp_s after the
  // amplifier is first ready (the loop at full gain).
  double start_s{-1.0};
};

struct RegenerativeCutReport {
  bool cut{false};
  std::string job;
  double requested_rpm{0.0}, rpm{0.0};  // rpm: the tooth period a whole number of loop periods
  double axial_mm{0.0}, radial_mm{0.0};
  int teeth{0}, steps_per_tooth{0}, revolutions{0}, settle_revolutions{0};
  double start_s{0.0}, end_s{0.0};
  bool complete{false};  // every revolution cut before the run ended
  milling::ChatterVerdict verdict;
  double peak_force_n{0.0};
  double sle_um{0.0};
};

class RegenerativeCut {
 public:
  // cfg: the emulator's cell; plant: its plant (the cutting force joins its excitations).
  // Throws config::ConfigError for a job that cannot be read, has no controller part, or an option out of range.
  RegenerativeCut(const config::Config& cfg, sim::Plant& plant, const RegenerativeCutOptions& o);

  [[nodiscard]] double rpm() const { return settings_.rpm; }
  // When the amplifier is first ready at plant time t (sets the start if it was automatic).
  void amplifier_ready(double t_s);
  // Around the plant's step at plant time t.
  void before_step(double t_s) noexcept;
  void after_step() noexcept;
  [[nodiscard]] bool active() const { return k_ > 0 && k_ < steps_; }
  [[nodiscard]] RegenerativeCutReport report() const;

 private:
  [[nodiscard]] Eigen::Vector2d displacement() const;
  sim::Plant& plant_;
  milling::Cutter cutter_;
  config::MaterialConfig material_;
  milling::CutSettings settings_;
  std::optional<milling::CutProcess> process_;
  std::unique_ptr<milling::ToolDynamics> tables_;  // the job's modal tables (none: null)
  config::Axis feed_{config::Axis::kX};
  std::size_t location_{0}, direction_{1};
  sim::HeldForce* force_{nullptr};
  double auto_delay_s_{0.0};
  RegenerativeCutReport rep_;
  std::size_t k_{0}, steps_{0};
  bool started_{false};
  Eigen::Vector2d f_{Eigen::Vector2d::Zero()}, q_start_{Eigen::Vector2d::Zero()}, last_{Eigen::Vector2d::Zero()}, previous_{Eigen::Vector2d::Zero()};
  std::vector<double> x_m_, y_m_;
  std::vector<double> forced_hz_;  // the known disturbances' frequencies, fitted and taken out before the verdict
};

[[nodiscard]] nlohmann::json regenerative_cut_json(const RegenerativeCutReport& r);

}  // namespace robodamp::hil
