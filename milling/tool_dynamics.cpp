#include "milling/tool_dynamics.hpp"

#include <cmath>
#include <stdexcept>

#include <unsupported/Eigen/MatrixFunctions>

#include "modal/receptance.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

std::vector<CutterModalTerm> cutter_modal_terms(const Structure& structure, config::Axis feed_axis) {
  // Machine (r, e) to cutter frame: a feed along +y makes the cutter's x the machine's y and its wall
  // normal the machine's -x (Structure::frf_cutter): (r, e) -> (1 - r, 1 - e), negated off the diagonal.
  auto add = [&](std::vector<CutterModalTerm>& out, int r, int e, double wn, double zeta, double a, double b) {
    if (feed_axis == config::Axis::kY) {
      const double sign = r == e ? 1.0 : -1.0;
      r = 1 - r, e = 1 - e, a *= sign, b *= sign;
    }
    out.push_back({r, e, wn, zeta, a, b});
  };
  std::vector<CutterModalTerm> out;
  const auto& modal = structure.modal_terms();
  for (int k = 0; k < 4; ++k)
    for (const auto& mode : modal[static_cast<std::size_t>(k)].modes) {
      const modal::ModeNumerator n = modal::mode_numerator(mode);
      add(out, k / 2, k % 2, kTwoPi * mode.natural_freq_hz, mode.damping_ratio, n.a, n.b);
    }
  // A robot model at a pose: mode r contributes phi_r phi_e / (s^2 + 2 zeta w s + w^2) to H_re, with the
  // mass-normalised TCP shape phi (docs/pose_dynamics.md).
  constexpr double kMinZeta = 1e-9;  // the links have no damping of their own
  for (const auto& chain : structure.pose_chains())
    for (const auto& md : chain->modes(Structure::kPoseModesForCut)) {
      const double wn = kTwoPi * md.freq_hz, zeta = std::max(kMinZeta, 0.5 * md.loss_factor);
      for (int r = 0; r < 2; ++r)
        for (int e = 0; e < 2; ++e)
          if (const double a = md.tcp_shape(r) * md.tcp_shape(e); a != 0.0 && wn > 0.0)
            add(out, r, e, wn, zeta, a, 0.0);
    }
  for (const auto& c : structure.controller_paths())
    for (const auto& m : c.path.modes)
      add(out, static_cast<int>(c.direction), static_cast<int>(c.excitation_direction), m.wn_rad_per_s, m.damping_ratio,
          m.a, m.b);
  return out;
}

ToolDynamics::ToolDynamics(const std::vector<CutterModalTerm>& terms, double step_s) : step_s_(step_s) {
  if (!(step_s > 0.0)) throw std::invalid_argument("ToolDynamics: the step must be > 0 s");
  // One block per (excitation, wn, zeta); the responses read it with their own (a, b).
  std::vector<std::size_t> block_of;
  struct Key {
    int excitation;
    double wn, zeta;
  };
  std::vector<Key> keys;
  for (const auto& t : terms) {
    std::size_t k = 0;
    while (k < keys.size() &&
           !(keys[k].excitation == t.excitation && keys[k].wn == t.wn_rad_per_s && keys[k].zeta == t.damping_ratio))
      ++k;
    if (k == keys.size()) keys.push_back({t.excitation, t.wn_rad_per_s, t.damping_ratio});
    block_of.push_back(k);
  }
  const auto n = static_cast<Eigen::Index>(2 * keys.size());
  a_ = Eigen::MatrixXd::Zero(n, n), b_ = Eigen::MatrixXd::Zero(n, 2), c_ = Eigen::MatrixXd::Zero(2, n);
  weights_[0].assign(keys.size(), Eigen::Vector2d::Zero());
  weights_[1].assign(keys.size(), Eigen::Vector2d::Zero());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(2 * k);
    // Van Loan: exp([[A, B, 0], [0, 0, 1], [0, 0, 0]] h) = [[Phi, int_0^h e^{As} B ds, int_0^h e^{As} B (h - s) ds], ...];
    // the last over h is the response to an input rising from 0 to 1 over the step.
    Eigen::Matrix4d big = Eigen::Matrix4d::Zero();
    big(0, 1) = 1.0;
    big(1, 0) = -keys[k].wn * keys[k].wn;
    big(1, 1) = -2.0 * keys[k].zeta * keys[k].wn;
    big(1, 2) = 1.0;
    big(2, 3) = 1.0;
    a_.block(i, i, 2, 2) = big.topLeftCorner(2, 2);
    b_(i + 1, keys[k].excitation) = 1.0;
    const Eigen::Matrix4d e = (big * step_s).exp();
    const Eigen::Vector2d held = e.block(0, 2, 2, 1), ramp = e.block(0, 3, 2, 1) / step_s;
    blocks_.push_back({e.topLeftCorner(2, 2), held, ramp, keys[k].excitation});
    highest_hz_ = std::max(highest_hz_, keys[k].wn / (kTwoPi));
  }
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const std::size_t k = block_of[t];
    weights_[terms[t].response][k] += Eigen::Vector2d(terms[t].a, terms[t].b);
    c_(terms[t].response, static_cast<Eigen::Index>(2 * k)) += terms[t].a;
    c_(terms[t].response, static_cast<Eigen::Index>(2 * k + 1)) += terms[t].b;
  }
}

void ToolDynamics::step(const Eigen::Vector2d& f0, const Eigen::Vector2d& f1) noexcept {
  for (Block& b : blocks_) {
    const int e = b.excitation;
    b.x = b.phi * b.x + b.gamma * f0(e) + b.ramp * (f1(e) - f0(e));
  }
}

Eigen::Vector2d ToolDynamics::predict(const Eigen::Vector2d& f) const noexcept {
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    const Eigen::Vector2d x = blocks_[k].phi * blocks_[k].x + blocks_[k].gamma * f(blocks_[k].excitation);
    q(0) += weights_[0][k].dot(x), q(1) += weights_[1][k].dot(x);
  }
  return q;
}

double ToolDynamics::output(int r) const noexcept {
  double y = 0.0;
  const auto& w = weights_[r];
  for (std::size_t k = 0; k < blocks_.size(); ++k) y += w[k].dot(blocks_[k].x);
  return y;
}

}  // namespace robodamp::milling
