// Stability lobes by the zero-order method (Altintas-Budak, docs/physics.md §2) and an independent
// direct test of the same characteristic equation. Off the real-time path.
//
// For each chatter frequency wc of a grid (fine across every resonance, logarithmic elsewhere) the
// oriented FRF Phi0 = [alpha][G(i wc)] has two eigenvalues, tracked as branches across the grid.
// Each gives Lambda = -1/eig, b_lim = -2 pi Lambda_R (1 + kappa^2) / (N kt), kappa = Lambda_I / Lambda_R,
// eps = pi - 2 atan(kappa), and on lobe j the spindle speed n = 60 wc / (N (eps + 2 pi j)). The lobe
// diagram at a speed is the minimum positive b_lim over branches, lobes and crossings.
//
// The direct test counts the zeros of D(s) = det(I + Lambda(s) Phi0(s)), Lambda(s) = -(N/4pi) kt b
// (1 - e^{-s tau}), in the right half plane by the winding of D(i w) (Nyquist; G and the delay are stable),
// and bisects on b for the critical depth at a speed.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "config/milling_config.hpp"
#include "milling/cutting.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

// What the cut contributes to the chatter equation.
struct ChatterProcess {
  int teeth{3};
  double kt_n_per_m2{0.0};
  Eigen::Matrix2d alpha{Eigen::Matrix2d::Zero()};  // directional matrix (cutter frame)
  config::Axis feed_axis{config::Axis::kX};
};
[[nodiscard]] ChatterProcess chatter_process(const config::ToolConfig& tool, const config::MaterialConfig& material,
                                             const config::CutConfig& cut);

// Depths in millimetres, as in every milling model and the job files (the chatter equation itself is
// solved in metres inside the model).
struct LobePoint {
  double rpm{0.0};
  double b_lim_mm{0.0};
  double chatter_hz{0.0};
  int lobe{0};
  int branch{0};
};

struct LobeDiagram {
  std::vector<LobePoint> curve;  // one per speed; b_lim_mm = +inf where no lobe reaches the speed
  LobePoint minimum;
  std::size_t frequency_points{0};
};

class LobeModel {
 public:
  LobeModel(const Structure& structure, const ChatterProcess& process, const config::LobesConfig& settings);

  // Oriented FRF Phi0 = [alpha] G_cutter(f), m/N.
  [[nodiscard]] Eigen::Matrix2cd oriented(double f_hz) const;

  // The lobe diagram at the configured speeds (linear interpolation along each lobe between grid points).
  [[nodiscard]] LobeDiagram diagram() const;
  // The zero-order limit at one speed, each lobe crossing refined by bisection on the chatter frequency.
  [[nodiscard]] std::optional<LobePoint> limit_at(double rpm) const;
  // The raw points of lobe j (every valid grid frequency and branch), for checks.
  [[nodiscard]] std::vector<LobePoint> lobe_points(int lobe) const;

  // det(I + Lambda Phi0) at depth b, speed and frequency: zero on the stability boundary.
  [[nodiscard]] Complex characteristic(double b_mm, double rpm, double f_hz) const;
  // Direct test: no root of the characteristic equation in the right half plane.
  [[nodiscard]] bool stable(double b_mm, double rpm) const;
  // Critical depth at a speed by bisection on the direct test (relative tolerance), mm.
  [[nodiscard]] double critical_depth_mm(double rpm, double rel_tol = 1e-4) const;

  [[nodiscard]] std::vector<double> speeds_rpm() const;

 private:
  struct Eval {
    Complex lambda[2];  // -1/eig per branch; NaN where the eigenvalue vanishes
  };
  [[nodiscard]] Eval evaluate(double f_hz, const Eval* previous) const;
  // The same in metres, the unit the chatter equation is solved in.
  [[nodiscard]] Complex characteristic_m(double b_m, double rpm, double f_hz) const;
  [[nodiscard]] bool stable_m(double b_m, double rpm) const;
  [[nodiscard]] double critical_depth_m(double rpm, double rel_tol) const;
  // A point found in metres, as the public one in millimetres.
  [[nodiscard]] static LobePoint in_mm(LobePoint metres);
  // b_lim, eps for a Lambda; nullopt unless b_lim > 0.
  [[nodiscard]] std::optional<std::pair<double, double>> depth_and_phase(Complex lambda) const;
  [[nodiscard]] double speed_rpm(double f_hz, double eps, int lobe) const;
  // Calls fn(branch, i, (b, eps) at i, (b, eps) at i + 1) for each grid segment where the branch can chatter
  // at both ends.
  template <typename Fn>
  void for_each_segment(Fn fn) const {
    for (int br = 0; br < 2; ++br)
      for (std::size_t i = 0; i + 1 < grid_hz_.size(); ++i) {
        const auto p1 = depth_and_phase(evals_[i].lambda[br]);
        const auto p2 = depth_and_phase(evals_[i + 1].lambda[br]);
        if (p1 && p2) fn(br, i, *p1, *p2);
      }
  }

  const Structure& structure_;
  ChatterProcess process_;
  config::LobesConfig settings_;
  std::vector<double> grid_hz_;
  std::vector<Eval> evals_;
};

}  // namespace robodamp::milling
