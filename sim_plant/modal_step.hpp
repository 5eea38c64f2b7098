// One internal step of the plant in modal block form (docs/simulation.md): the exact zero-order-hold
// discretisation of PlantModel's state-space, stored as the blocks its structure has.
//   - The actuator's proof mass [p, p'] is a 2x2 block (fixed-size Eigen) driven by the delayed coil
//     voltage (Eq. 3).
//   - Each structural mode block [q, q'] (one per mode and excitation location) is a 2x2 block driven by its
//     own state, the external force at its location and, for a mode excited at the actuator location, the
//     actuator's state and coil voltage.
// Every other entry of e^{A h} is exactly zero (checked at construction), so a step costs 3 two-wide
// multiply-adds per free mode block and 7 per actuator-driven one (fixed-size Eigen 2-vectors: a block's
// two rows are one SIMD register), with no branch per block. The blocks are grouped by kind and location.
// Construction allocates; advance() and output() are RT-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "sim_plant/state_space.hpp"

namespace robodamp::sim {

class ModalStep {
 public:
  ModalStep() = default;
  // ss: the plant (states [p, p', q_0, q_0', q_1, ...], inputs [coil, force at each location]);
  // coil: its discretisation with the actuator delay; force_gamma: the external forces' ZOH input matrix.
  // Throws std::logic_error when e^{A h} does not have the block structure (a PlantModel bug).
  ModalStep(const StateSpace& ss, const DelayedZoh& coil, const Matrix& force_gamma);

  [[nodiscard]] std::size_t states() const { return 2 + 2 * x_.size(); }
  [[nodiscard]] std::size_t mode_blocks() const { return x_.size(); }

  void reset() noexcept;
  // x <- phi x + gamma_late u_late + gamma_early u_early + gamma_force f (f: one force per location, N).
  void advance(double u_late_v, double u_early_v, const double* force_n) noexcept;
  // Output row of ss (C x + D u) at the current state with inputs u = [coil, forces...].
  [[nodiscard]] double output(std::size_t row, const double* u) const noexcept;
  // The whole state in ss's order (tests and cross-checks; allocates).
  [[nodiscard]] Vector state() const;
  // Sets it (same order and size as state()); throws std::invalid_argument on another size.
  void set_state(const Vector& x);

 private:
  // Consecutive blocks [begin, end) driven by the force at one location (and the actuator or not).
  struct Group {
    std::uint32_t begin, end, location;
  };
  // Per block (in the step's order), its two rows as columns of e^{A h} and the input matrices:
  // [q, q']+ = q col_q + q' col_qd + f force (+ p col_p + p' col_v + u_late late + u_early early if driven).
  struct FreeBlock {
    Eigen::Vector2d col_q, col_qd, force;
  };
  struct DrivenBlock {
    Eigen::Vector2d col_q, col_qd, force, col_p, col_v, late, early;
  };
  Eigen::Matrix2d act_phi_;
  Eigen::Vector2d act_late_, act_early_;
  Eigen::Vector2d act_;  // [p, p']
  std::vector<Group> driven_, free_;
  std::vector<DrivenBlock> driven_blocks_;
  std::vector<FreeBlock> free_blocks_;
  std::vector<Eigen::Vector2d> x_;       // [q, q'] per block: the driven ones, then the free ones
  std::vector<std::uint32_t> ss_block_;  // step order -> block index in ss
  // Output rows: [row][2] actuator, [row][block] position and velocity weights, [row][input] direct.
  std::vector<double> c_act_, c_x_, d_;  // c_x_: [row][block][q, q']
  std::size_t inputs_{0};
};

}  // namespace robodamp::sim
