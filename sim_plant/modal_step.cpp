#include "sim_plant/modal_step.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace robodamp::sim {

namespace {

[[noreturn]] void structure_error(const std::string& what) { throw std::logic_error("ModalStep: " + what); }

// The location whose force drives block rows [r, r + 1] in B (0 when none does); more than one is a bug.
std::uint32_t driving_location(const Matrix& b, Eigen::Index r) {
  Eigen::Index found = -1;
  for (Eigen::Index l = 1; l < b.cols(); ++l)
    if (b(r, l) != 0.0 || b(r + 1, l) != 0.0) {
      if (found >= 0) structure_error("a mode block is driven by the forces at two locations");
      found = l - 1;
    }
  return static_cast<std::uint32_t>(std::max<Eigen::Index>(found, 0));
}

// Groups of consecutive blocks with the same location, over step order [begin, end).
template <class Group>
void group_by_location(const std::vector<std::uint32_t>& location, std::size_t begin, std::size_t end,
                       std::vector<Group>& out) {
  for (std::size_t i = begin; i < end;) {
    std::size_t j = i;
    while (j < end && location[j] == location[i]) ++j;
    out.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j), location[i]});
    i = j;
  }
}

}  // namespace

ModalStep::ModalStep(const StateSpace& ss, const DelayedZoh& coil, const Matrix& force_gamma) {
  const Eigen::Index n = ss.a.rows();
  if (n < 2 || (n - 2) % 2 != 0 || coil.phi.rows() != n || force_gamma.rows() != n)
    structure_error("the plant must be [p, p'] and 2-state mode blocks");
  const Matrix& phi = coil.phi;
  // The structure is read from A and B, where it is exact: the actuator is driven by nothing but itself
  // and the coil, a mode block by itself, the actuator and the force at one location. e^{A h} then has the
  // same structure; the entries outside it that the matrix exponential leaves (its LU pivots rows) are
  // rounding, at most ~1e-16 of the largest entry, and are not kept.
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c) {
      const Eigen::Index rb = r < 2 ? -1 : (r - 2) / 2, cb = c < 2 ? -1 : (c - 2) / 2;
      if (!(rb == cb || (rb >= 0 && cb == -1)) && ss.a(r, c) != 0.0)
        structure_error("A(" + std::to_string(r) + ", " + std::to_string(c) + ") couples two blocks");
    }
  if (ss.b.topRightCorner(2, ss.b.cols() - 1).cwiseAbs().maxCoeff() != 0.0)
    structure_error("an external force drives the proof mass");
  act_phi_ = phi.topLeftCorner(2, 2);
  act_late_ = coil.gamma_late.topRows(2);
  act_early_ = coil.gamma_early.topRows(2);
  act_.setZero();

  // Step order: the actuator-driven blocks first, then the free ones, each sorted by location.
  const auto blocks = static_cast<std::size_t>((n - 2) / 2);
  std::vector<std::uint32_t> location(blocks);
  std::vector<bool> driven(blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    const auto r = static_cast<Eigen::Index>(2 + 2 * b);
    location[b] = driving_location(ss.b, r);
    driven[b] =
        ss.a.block(r, 0, 2, 2).cwiseAbs().maxCoeff() != 0.0 || ss.b.block(r, 0, 2, 1).cwiseAbs().maxCoeff() != 0.0;
  }
  ss_block_.resize(blocks);
  std::iota(ss_block_.begin(), ss_block_.end(), 0U);
  std::stable_sort(ss_block_.begin(), ss_block_.end(), [&](std::uint32_t x, std::uint32_t y) {
    return driven[x] != driven[y] ? static_cast<bool>(driven[x]) : location[x] < location[y];
  });
  const auto n_driven = static_cast<std::size_t>(std::count(driven.begin(), driven.end(), true));
  std::vector<std::uint32_t> step_location(blocks);
  for (std::size_t i = 0; i < blocks; ++i) step_location[i] = location[ss_block_[i]];
  group_by_location(step_location, 0, n_driven, driven_);
  group_by_location(step_location, n_driven, blocks, free_);

  x_.assign(blocks, Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < blocks; ++i) {
    const auto r = static_cast<Eigen::Index>(2 + 2 * ss_block_[i]);
    const auto l = static_cast<Eigen::Index>(step_location[i]);
    const Eigen::Vector2d col_q = phi.block(r, r, 2, 1), col_qd = phi.block(r, r + 1, 2, 1);
    const Eigen::Vector2d force = force_gamma.block(r, l, 2, 1);
    if (i < n_driven)
      driven_blocks_.push_back({col_q, col_qd, force, phi.block(r, 0, 2, 1), phi.block(r, 1, 2, 1),
                                coil.gamma_late.block(r, 0, 2, 1), coil.gamma_early.block(r, 0, 2, 1)});
    else
      free_blocks_.push_back({col_q, col_qd, force});
  }

  const auto rows = static_cast<std::size_t>(ss.c.rows());
  inputs_ = static_cast<std::size_t>(ss.d.cols());
  c_act_.resize(2 * rows), c_x_.resize(rows * 2 * blocks), d_.resize(rows * inputs_);
  for (std::size_t row = 0; row < rows; ++row) {
    const auto r = static_cast<Eigen::Index>(row);
    c_act_[2 * row] = ss.c(r, 0), c_act_[2 * row + 1] = ss.c(r, 1);
    for (std::size_t i = 0; i < blocks; ++i) {
      c_x_[(row * blocks + i) * 2] = ss.c(r, 2 + 2 * static_cast<Eigen::Index>(ss_block_[i]));
      c_x_[(row * blocks + i) * 2 + 1] = ss.c(r, 3 + 2 * static_cast<Eigen::Index>(ss_block_[i]));
    }
    for (std::size_t u = 0; u < inputs_; ++u) d_[row * inputs_ + u] = ss.d(r, static_cast<Eigen::Index>(u));
  }
}

void ModalStep::reset() noexcept {
  act_.setZero();
  for (auto& x : x_) x.setZero();
}

void ModalStep::advance(double u_late_v, double u_early_v, const double* force_n) noexcept {
  const double p = act_(0), v = act_(1);
  Eigen::Vector2d* x = x_.data();
  for (const Group& g : driven_) {
    const double f = force_n[g.location];
    for (std::uint32_t i = g.begin; i < g.end; ++i) {
      const DrivenBlock& b = driven_blocks_[i];
      x[i] = b.col_q * x[i](0) + b.col_qd * x[i](1) + b.force * f + b.col_p * p + b.col_v * v + b.late * u_late_v +
             b.early * u_early_v;
    }
  }
  const std::size_t offset = driven_blocks_.size();
  for (const Group& g : free_) {
    const double f = force_n[g.location];
    for (std::uint32_t i = g.begin; i < g.end; ++i) {
      const FreeBlock& b = free_blocks_[i - offset];
      x[i] = b.col_q * x[i](0) + b.col_qd * x[i](1) + b.force * f;
    }
  }
  act_ = act_phi_ * act_ + act_late_ * u_late_v + act_early_ * u_early_v;
}

double ModalStep::output(std::size_t row, const double* u) const noexcept {
  using Map = Eigen::Map<const Eigen::VectorXd>;
  const auto n = static_cast<Eigen::Index>(2 * x_.size());
  double y = c_act_[2 * row] * act_(0) + c_act_[2 * row + 1] * act_(1);
  y += Map(c_x_.data() + row * 2 * x_.size(), n).dot(Map(x_.data()->data(), n));
  for (std::size_t i = 0; i < inputs_; ++i) y += d_[row * inputs_ + i] * u[i];
  return y;
}

Vector ModalStep::state() const {
  Vector x(static_cast<Eigen::Index>(states()));
  x.head(2) = act_;
  for (std::size_t i = 0; i < x_.size(); ++i) x.segment(2 + 2 * static_cast<Eigen::Index>(ss_block_[i]), 2) = x_[i];
  return x;
}

void ModalStep::set_state(const Vector& x) {
  if (x.size() != static_cast<Eigen::Index>(states()))
    throw std::invalid_argument("ModalStep::set_state: " + std::to_string(x.size()) + " states for a plant of " +
                                std::to_string(states()));
  act_ = x.head(2);
  for (std::size_t i = 0; i < x_.size(); ++i) x_[i] = x.segment(2 + 2 * static_cast<Eigen::Index>(ss_block_[i]), 2);
}

}  // namespace robodamp::sim
