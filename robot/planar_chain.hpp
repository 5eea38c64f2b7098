// A planar serial robot for pose-dependent dynamics (docs/pose_dynamics.md; the planar-robot study): links as
// Euler-Bernoulli frame elements (axial and bending, consistent mass), joined by torsional joint springs
// with hysteretic damping (k (1 + 2 i zeta)), the first joint to a rigid base, and the spindle head as a
// lumped mass and rotary inertia at the tool centre point (TCP). A pose is the joint angles (each link's
// angle relative to the previous link; joint 1's relative to the base's x axis).
//
// The TCP receptance (2x2, machine frame x-y) comes two ways that must agree: by assembling the whole
// model's dynamic stiffness and solving it, and by receptance coupling of substructures (RCSA, the planar-robot study
// Figure 2): each link free-free, coupled link by link through its joint (translations rigid, rotation
// through the spring's compliance), the first to the ground. Off the real-time path.
#pragma once

#include <complex>
#include <vector>

#include <Eigen/Dense>

namespace robodamp::robot {

using Complex = std::complex<double>;

struct Link {
  double length_m{1.0};
  double mass_kg{10.0};               // distributed uniformly along the link
  double bending_stiffness_nm2{1e7};  // E I
  double axial_stiffness_n{1e9};      // E A
  int elements{4};
};

struct Joint {
  double stiffness_nm_per_rad{1e5};
  double damping_ratio{0.02};  // hysteretic: the spring is k (1 + 2 i zeta)
  // The joint's bearings in translation (x and y alike, the same hysteretic damping): 0 = rigid, the
  // translations shared. A compliance the torsional-only model lacks (docs/pose_dynamics.md).
  double translational_stiffness_n_per_m{0.0};
};

struct ChainModel {
  std::vector<Link> links;
  std::vector<Joint> joints;  // joint i drives link i (joint 0: base to link 0)
  double head_mass_kg{0.0};
  double head_inertia_kgm2{0.0};
};

struct Mode {
  double freq_hz{0.0};
  Eigen::VectorXd shape;  // over the assembled DOFs
  double tcp_modal_stiffness_n_per_m{
      0.0};  // in the direction it moves the TCP most (k = w^2 / (phi_tcp^2 / phi' M phi))
  double tcp_direction_rad{0.0};
  Eigen::Vector2d tcp_shape{0.0, 0.0};  // the mass-normalised shape's TCP x and y, 1/sqrt(kg)
  double loss_factor{0.0};              // phi' Im(K) phi / phi' Re(K) phi: the joints' hysteretic share
};

// A mode's viscous damping ratio as the plant and the schedule's analysis model it (docs/pose_dynamics.md):
// half its loss factor, at least 1e-3 (a mode without joint damping still gets a little).
inline constexpr double kMinModalDampingRatio = 1e-3;
[[nodiscard]] double modal_damping_ratio(const Mode& m);

// The TCP receptance matrix, m/N, of these modes alone with their viscous damping ratios: the plant the
// emulator runs and the schedule's analysis predicts with at a pose (analysis::pose_modes).
[[nodiscard]] Eigen::Matrix2cd modal_tcp_frf(const std::vector<Mode>& modes, double f_hz);

// Element matrices in the element's own axes (u1 v1 th1 u2 v2 th2).
struct ElementMatrices {
  Eigen::Matrix<double, 6, 6> k, m;
};
[[nodiscard]] ElementMatrices frame_element(double length_m, double mass_per_m_kg, double ei_nm2, double ea_n);

class PlanarChain {
 public:
  // Throws std::invalid_argument when the model is not physical (non-positive lengths, masses,
  // stiffnesses, element counts; joint count not equal to link count; angle count wrong).
  PlanarChain(ChainModel model, std::vector<double> joint_angles_rad);

  [[nodiscard]] const ChainModel& model() const { return m_; }
  [[nodiscard]] Eigen::Vector2d tcp_position_m() const;
  [[nodiscard]] std::size_t dofs() const { return static_cast<std::size_t>(k_.rows()); }

  // The whole model assembled: undamped modes (ascending) and the TCP receptance matrix, m/N.
  [[nodiscard]] std::vector<Mode> modes(std::size_t count) const;
  [[nodiscard]] Eigen::Matrix2cd tcp_frf_direct(double f_hz) const;
  // The same by receptance coupling of the links' free-free receptances.
  [[nodiscard]] Eigen::Matrix2cd tcp_frf_rcsa(double f_hz) const;

 private:
  struct Placement {
    std::vector<int> node_dof;  // first DOF (x) of each of the link's nodes in the assembly; th is separate
    std::vector<int> node_rot;  // rotation DOF of each node
  };
  void assemble();
  // One link's free-free dynamic stiffness over its own nodes (3 per node: x, y, th), with the head on
  // the last link.
  [[nodiscard]] Eigen::MatrixXcd link_dynamic_stiffness(std::size_t i, double w) const;

  ChainModel m_;
  std::vector<double> angles_;  // absolute angle of each link
  std::vector<Eigen::Vector2d> start_;
  Eigen::MatrixXcd k_;  // complex stiffness (joint damping)
  Eigen::MatrixXd m_mass_;
  int tcp_x_{0}, tcp_rot_{0};
};

}  // namespace robodamp::robot
