// The tool-workpiece structure in time, in the cutter's frame (x = feed, y = wall normal): the modal
// tables of the job's structure (every part, 2x2 with cross terms, residue or modal-stiffness form,
// Eq. 1) and the open-loop robot FRF of its controller parts, as one modal state-space with a 2-state
// block per (mode, force direction) that the direction pairs share (docs/milling.md, "Time domain").
// Discretised exactly at the simulation step for a force that is held (zero-order hold) or varies linearly
// over the step (first-order hold, what the cut simulation uses with a predicted end-of-step force).
// Construction allocates; step() and predict() do not.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "config/milling_config.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

// One continuous modal term in the cutter frame: (a + b s) / (s^2 + 2 zeta wn s + wn^2) from the force
// along `excitation` to the displacement along `response` (0 = x, 1 = y), m/N.
struct CutterModalTerm {
  int response{0}, excitation{0};
  double wn_rad_per_s{0.0}, damping_ratio{0.0}, a{0.0}, b{0.0};
};

// The open-loop structure's modal terms in the cutter frame for a feed along feed_axis.
[[nodiscard]] std::vector<CutterModalTerm> cutter_modal_terms(const Structure& structure, config::Axis feed_axis);

// What the cut simulation steps: the tool's displacement relative to the workpiece (cutter frame) under the
// cutting force held over each step.
class CutDynamics {
 public:
  virtual ~CutDynamics() = default;
  [[nodiscard]] virtual double step_s() const = 0;
  [[nodiscard]] virtual Eigen::Vector2d displacement() const = 0;  // m
  // The displacement at the end of the next step with the force f held (an estimate where not exact), m.
  [[nodiscard]] virtual Eigen::Vector2d predict(const Eigen::Vector2d& f_n) const = 0;
  virtual void step(const Eigen::Vector2d& f_n) = 0;
  // Called once when the statistics start (after the settling revolutions).
  virtual void settled() {}
};

class ToolDynamics final : public CutDynamics {
 public:
  ToolDynamics(const std::vector<CutterModalTerm>& terms, double step_s);

  // Advances one step with the force on the tool (cutter frame, N) going linearly from f0 to f1 over it
  // (f1 = f0: held).
  void step(const Eigen::Vector2d& f0_n, const Eigen::Vector2d& f1_n) noexcept;
  void step(double fx_n, double fy_n) noexcept { step({fx_n, fy_n}, {fx_n, fy_n}); }
  void step(const Eigen::Vector2d& f_n) override { step(f_n, f_n); }
  // The displacement one step ahead with the force f held, state unchanged, m.
  [[nodiscard]] Eigen::Vector2d predict(const Eigen::Vector2d& f_n) const noexcept override;
  // Tool displacement relative to the workpiece (cutter frame), m.
  [[nodiscard]] Eigen::Vector2d displacement() const noexcept override { return {output(0), output(1)}; }
  [[nodiscard]] double step_s() const override { return step_s_; }
  [[nodiscard]] std::size_t blocks() const { return blocks_.size(); }
  // The continuous model (states [q_0, q_0', q_1, ...], inputs [fx, fy], outputs [x, y]): SDM uses it.
  [[nodiscard]] const Eigen::MatrixXd& a() const { return a_; }
  [[nodiscard]] const Eigen::MatrixXd& b() const { return b_; }
  [[nodiscard]] const Eigen::MatrixXd& c() const { return c_; }
  // Highest natural frequency, Hz.
  [[nodiscard]] double highest_mode_hz() const { return highest_hz_; }

 private:
  struct Block {
    Eigen::Matrix2d phi;
    Eigen::Vector2d gamma;  // held input
    Eigen::Vector2d ramp;   // input rising linearly from 0 to 1 over the step
    int excitation{0};
    Eigen::Vector2d x{Eigen::Vector2d::Zero()};
  };
  [[nodiscard]] double output(int r) const noexcept;
  double step_s_;
  double highest_hz_{0.0};
  std::vector<Block> blocks_;
  std::vector<Eigen::Vector2d> weights_[2];  // [response][block]: (a, b) on (q, q')
  Eigen::MatrixXd a_, b_, c_;
};

}  // namespace robodamp::milling
