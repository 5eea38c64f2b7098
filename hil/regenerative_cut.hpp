// The HIL emulator's regenerative cut (docs/milling.md, "The cut across processes"): the time-domain cut
// of milling/ (surface memory per slice and angle, helix, runout, loss of contact, the job's force model)
// stepped against the emulated robot, whose actuator a separate robodamp run drives through the CAN and
// Modbus path. The cutting force acts on the plant at the job's controller part (its location and
// direction); the job's modal tables (the tool, the workpiece) are stepped beside it, as the in-process
// damped cut (milling/damped_dynamics.hpp) does with the Controller in the same loop. The speed is made a
// whole number of loop periods per tooth, as there.
//
// The robot program may change the spindle speed and the depth during the cut (steps and ramps, plant
// time; a ramp as the robot's register staircase), and the robot may follow robodamp's spindle-speed
// advice (follow_advice). Each change continues the cut on a new CutProcess (milling::CutProcess::
// continue_from: the surface, the angle and the feed carry over) and starts a segment; each segment is
// classified by the in-process cut's chatter detector at report(), so the two processes' verdicts
// compare. The cut ends `revolutions` revolutions into a segment after the program's last change and
// after until_s (the robot's path). Beside
// it the live chatter indicator (milling::ChatterMonitor, as robodamp run's) watches the control
// accelerometer, which times detection and quiet. Built before the run (allocates); the per-step calls
// do not, except a change of speed or depth, which builds the next process (rare, between steps).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/chatter.hpp"
#include "milling/chatter_indicator.hpp"
#include "hil/cutting_load.hpp"
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
  // The robot program (plant time): speed (rpm) and depth (mm) steps and ramps from the values above.
  std::vector<SpindleChange> spindle, depth;
  double program_period_s{0.05};  // how often the program's ramps step (the robot's register period)
  // The tool stays in the cut at least until this plant time (the robot's path), s; 0: no such bound.
  double until_s{0.0};
  // A robot program that waits for robodamp's word: the tool stays in the cut until the robot has read
  // an advice (followed, kept or refused), then the last speed's revolutions.
  bool until_advice{false};
};

// One span of the cut at one speed and depth.
struct CutSegment {
  std::string cause;  // "start", "program", "advice"
  double start_s{0.0}, end_s{0.0};
  double requested_rpm{0.0}, rpm{0.0}, axial_mm{0.0};
  int steps_per_tooth{0};
  double revolutions{0.0};
  bool judged{false};  // long enough for the detector (settle_revolutions + 8)
  milling::ChatterVerdict verdict;
  // The live indicator (as robodamp run's) on the control accelerometer: first chatter in this segment,
  // and, after chatter in the one before, the first quiet evaluation (negative: none).
  double indicator_chatter_s{-1.0}, indicator_quiet_s{-1.0};
};

// What the last segment's fields below say of the whole cut: the segment the cut ended in.
struct RegenerativeCutReport {
  bool cut{false};
  std::string job;
  double requested_rpm{0.0}, rpm{0.0};  // rpm: the tooth period a whole number of loop periods
  double axial_mm{0.0}, radial_mm{0.0};
  std::vector<CutSegment> segments;  // in order; the last is the one the fields above describe
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

  // The speed the spindle turns now (the robot's register shows it), rpm.
  [[nodiscard]] double rpm() const { return settings_.rpm; }
  [[nodiscard]] double axial_mm() const { return settings_.cut.axial_mm; }
  // When the amplifier is first ready at plant time t (sets the start if it was automatic).
  void amplifier_ready(double t_s);
  // The robot follows an advised speed from plant time t (it overrides the program's speed from then).
  void follow_advice(double rpm, double t_s);
  // The robot read an advice at plant time t (whatever it did with it).
  void advice_read(double t_s);
  // Around the plant's step at plant time t.
  void before_step(double t_s);
  void after_step() noexcept;
  // The control accelerometer's sample this step (the live indicator's input).
  void sensed(double accel_mps2, double t_s);
  [[nodiscard]] bool active() const { return started_ && !ended_; }
  [[nodiscard]] bool ended() const { return ended_; }
  [[nodiscard]] RegenerativeCutReport report() const;

 private:
  struct Segment {
    CutSegment head;
    std::size_t steps{0};
    std::vector<double> x_m, y_m;
    std::uint64_t engaged{0}, out_of_cut{0};
  };
  [[nodiscard]] Eigen::Vector2d displacement() const;
  [[nodiscard]] milling::CutSettings settings_for(double rpm, double axial_mm) const;
  void change_to(double requested_rpm, double axial_mm, const char* cause, double t_s);
  // A segment at the settings now, from plant time t (its record reserved for `revolutions` revolutions).
  void start_segment(const char* cause, double t_s);
  [[nodiscard]] CutSegment judged(const Segment& s) const;
  sim::Plant& plant_;
  milling::Cutter cutter_;
  config::MaterialConfig material_;
  milling::CutSettings settings_;
  std::optional<milling::CutProcess> process_;
  std::size_t process_k_{0};  // the process's next step index
  SpindleProfile speed_, depth_;
  double program_end_s_{0.0}, program_period_s_{0.05}, next_program_s_{0.0};
  double advised_rpm_{0.0};  // > 0: the robot follows it
  bool awaiting_advice_{false};
  double requested_rpm_{0.0};
  std::vector<Segment> segments_;
  milling::ChatterMonitor indicator_;
  double next_indicator_s_{0.0};
  std::unique_ptr<milling::ToolDynamics> tables_;  // the job's modal tables (none: null)
  config::Axis feed_{config::Axis::kX};
  std::size_t location_{0}, direction_{1};
  sim::HeldForce* force_{nullptr};
  double auto_delay_s_{0.0};
  RegenerativeCutReport rep_;
  bool started_{false}, ended_{false};
  double t_s_{0.0};
  Eigen::Vector2d f_{Eigen::Vector2d::Zero()}, q_start_{Eigen::Vector2d::Zero()}, last_{Eigen::Vector2d::Zero()},
      previous_{Eigen::Vector2d::Zero()};
  double drive_hz_{0.0};  // the drives' vibration: its lines are fitted and taken out before each verdict
};

[[nodiscard]] nlohmann::json regenerative_cut_json(const RegenerativeCutReport& r);

}  // namespace robodamp::hil
