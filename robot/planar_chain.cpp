#include "robot/planar_chain.hpp"
#include "units/units.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

namespace robodamp::robot {

namespace {

Eigen::Matrix<double, 6, 6> rotation(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  Eigen::Matrix<double, 6, 6> t = Eigen::Matrix<double, 6, 6>::Zero();
  for (int n = 0; n < 2; ++n) {  // local (u, v) = R (x, y) at each node
    t(3 * n, 3 * n) = c, t(3 * n, 3 * n + 1) = s;
    t(3 * n + 1, 3 * n) = -s, t(3 * n + 1, 3 * n + 1) = c;
    t(3 * n + 2, 3 * n + 2) = 1.0;
  }
  return t;
}

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

Complex joint_stiffness(const Joint& j) {
  return {j.stiffness_nm_per_rad, 2.0 * j.damping_ratio * j.stiffness_nm_per_rad};
}
Complex joint_translational_stiffness(const Joint& j) {
  return {j.translational_stiffness_n_per_m, 2.0 * j.damping_ratio * j.translational_stiffness_n_per_m};
}
bool translation_rigid(const Joint& j) { return !(j.translational_stiffness_n_per_m > 0.0); }

}  // namespace

ElementMatrices frame_element(double l, double mass_per_m, double ei, double ea) {
  ElementMatrices e;
  e.k.setZero();
  e.m.setZero();
  // Axial: u1 (0), u2 (3).
  const double ka = ea / l;
  e.k(0, 0) = e.k(3, 3) = ka, e.k(0, 3) = e.k(3, 0) = -ka;
  const double ma = mass_per_m * l / 6.0;
  e.m(0, 0) = e.m(3, 3) = 2.0 * ma, e.m(0, 3) = e.m(3, 0) = ma;
  // Bending (Euler-Bernoulli, cubic Hermite shape functions): v1 th1 v2 th2 = 1 2 4 5.
  const int b[4] = {1, 2, 4, 5};
  const double kb = ei / (l * l * l);
  const double kbend[4][4] = {{12, 6 * l, -12, 6 * l},
                              {6 * l, 4 * l * l, -6 * l, 2 * l * l},
                              {-12, -6 * l, 12, -6 * l},
                              {6 * l, 2 * l * l, -6 * l, 4 * l * l}};
  const double mb = mass_per_m * l / 420.0;
  const double mbend[4][4] = {{156, 22 * l, 54, -13 * l},
                              {22 * l, 4 * l * l, 13 * l, -3 * l * l},
                              {54, 13 * l, 156, -22 * l},
                              {-13 * l, -3 * l * l, -22 * l, 4 * l * l}};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e.k(b[r], b[c]) = kb * kbend[r][c], e.m(b[r], b[c]) = mb * mbend[r][c];
  return e;
}

PlanarChain::PlanarChain(ChainModel model, std::vector<double> joint_angles_rad) : m_(std::move(model)) {
  check(!m_.links.empty(), "robot model: no links");
  check(m_.joints.size() == m_.links.size(), "robot model: one joint per link (" + std::to_string(m_.links.size()) +
                                                 " links, " + std::to_string(m_.joints.size()) + " joints)");
  check(joint_angles_rad.size() == m_.links.size(), "pose: " + std::to_string(joint_angles_rad.size()) +
                                                        " joint angles for " + std::to_string(m_.links.size()) +
                                                        " joints");
  for (std::size_t i = 0; i < m_.links.size(); ++i) {
    const Link& l = m_.links[i];
    const Joint& j = m_.joints[i];
    const std::string n = std::to_string(i + 1);
    check(std::isfinite(joint_angles_rad[i]), "pose: joint " + n + " angle is not a number");
    check(l.length_m > 0.0 && std::isfinite(l.length_m), "link " + n + ": length_m must be > 0 m");
    check(l.mass_kg > 0.0 && std::isfinite(l.mass_kg), "link " + n + ": mass_kg must be > 0 kg");
    check(l.bending_stiffness_nm2 > 0.0 && std::isfinite(l.bending_stiffness_nm2),
          "link " + n + ": bending stiffness must be > 0 N m^2");
    check(l.axial_stiffness_n > 0.0 && std::isfinite(l.axial_stiffness_n),
          "link " + n + ": axial stiffness must be > 0 N");
    check(l.elements >= 1 && l.elements <= 64, "link " + n + ": elements must be 1..64");
    check(j.stiffness_nm_per_rad > 0.0 && std::isfinite(j.stiffness_nm_per_rad),
          "joint " + n + ": stiffness must be > 0 N m/rad");
    check(j.damping_ratio >= 0.0 && j.damping_ratio < 1.0, "joint " + n + ": damping ratio must be in [0, 1)");
    check(j.translational_stiffness_n_per_m >= 0.0 && std::isfinite(j.translational_stiffness_n_per_m),
          "joint " + n + ": translational stiffness must be >= 0 N/m (0: rigid)");
  }
  check(m_.head_mass_kg >= 0.0 && m_.head_inertia_kgm2 >= 0.0, "head: mass and inertia must be >= 0");
  double a = 0.0;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < m_.links.size(); ++i) {
    a += joint_angles_rad[i];
    angles_.push_back(a);
    start_.push_back(p);
    p += m_.links[i].length_m * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  assemble();
}

Eigen::Vector2d PlanarChain::tcp_position_m() const {
  const auto& l = m_.links.back();
  return start_.back() + l.length_m * Eigen::Vector2d(std::cos(angles_.back()), std::sin(angles_.back()));
}

void PlanarChain::assemble() {
  // DOF numbering: each node has its own rotation; translations are shared at a rigid joint (link i's
  // first node is link i-1's last) and fixed at the base; a joint with translational stiffness gives
  // link i's first node translations of its own, tied to link i-1's last (or the base) by that spring.
  struct NodeDofs {
    int x, rot;  // x = -1: fixed translation
  };
  std::vector<std::vector<NodeDofs>> nodes(m_.links.size());
  int n = 0;
  int prev_x = -1;
  for (std::size_t i = 0; i < m_.links.size(); ++i) {
    for (int j = 0; j <= m_.links[i].elements; ++j) {
      NodeDofs d{};
      if (j == 0 && translation_rigid(m_.joints[i]))
        d.x = prev_x;
      else
        d.x = n, n += 2;
      d.rot = n++;
      nodes[i].push_back(d);
    }
    prev_x = nodes[i].back().x;
  }
  k_ = Eigen::MatrixXcd::Zero(n, n);
  m_mass_ = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < m_.links.size(); ++i) {
    const Link& l = m_.links[i];
    const double le = l.length_m / l.elements;
    const ElementMatrices e = frame_element(le, l.mass_kg / l.length_m, l.bending_stiffness_nm2, l.axial_stiffness_n);
    const Eigen::Matrix<double, 6, 6> t = rotation(angles_[i]);
    const Eigen::Matrix<double, 6, 6> kg = t.transpose() * e.k * t, mg = t.transpose() * e.m * t;
    for (int el = 0; el < l.elements; ++el) {
      int dof[6];
      for (int s = 0; s < 2; ++s) {
        const NodeDofs d = nodes[i][static_cast<std::size_t>(el + s)];
        dof[3 * s] = d.x, dof[3 * s + 1] = d.x < 0 ? -1 : d.x + 1, dof[3 * s + 2] = d.rot;
      }
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
          if (dof[r] >= 0 && dof[c] >= 0) k_(dof[r], dof[c]) += kg(r, c), m_mass_(dof[r], dof[c]) += mg(r, c);
    }
    // Joint i: between the previous link's last rotation (or the base) and this link's first.
    const Complex kj = joint_stiffness(m_.joints[i]);
    if (!translation_rigid(m_.joints[i])) {
      const Complex kt = joint_translational_stiffness(m_.joints[i]);
      const int own = nodes[i].front().x, shared = i > 0 ? nodes[i - 1].back().x : -1;
      for (int c = 0; c < 2; ++c) {
        k_(own + c, own + c) += kt;
        if (shared < 0) continue;
        k_(shared + c, shared + c) += kt, k_(shared + c, own + c) -= kt, k_(own + c, shared + c) -= kt;
      }
    }
    const int b = nodes[i].front().rot;
    k_(b, b) += kj;
    if (i > 0) {
      const int a = nodes[i - 1].back().rot;
      k_(a, a) += kj, k_(a, b) -= kj, k_(b, a) -= kj;
    }
  }
  const NodeDofs tcp = nodes.back().back();
  tcp_x_ = tcp.x, tcp_rot_ = tcp.rot;
  m_mass_(tcp_x_, tcp_x_) += m_.head_mass_kg;
  m_mass_(tcp_x_ + 1, tcp_x_ + 1) += m_.head_mass_kg;
  m_mass_(tcp_rot_, tcp_rot_) += m_.head_inertia_kgm2;
}

double modal_damping_ratio(const Mode& m) { return std::max(kMinModalDampingRatio, 0.5 * m.loss_factor); }

Eigen::Matrix2cd modal_tcp_frf(const std::vector<Mode>& modes, double f_hz) {
  const double w = kTwoPi * f_hz;
  Eigen::Matrix2cd g = Eigen::Matrix2cd::Zero();
  for (const Mode& md : modes) {
    const double wr = kTwoPi * md.freq_hz;
    const Complex den(wr * wr - w * w, 2.0 * modal_damping_ratio(md) * wr * w);
    g += (md.tcp_shape * md.tcp_shape.transpose()).cast<Complex>() / den;
  }
  return g;
}

std::vector<Mode> PlanarChain::modes(std::size_t count) const {
  const Eigen::MatrixXd kr = k_.real();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(kr, m_mass_);  // mass-normalised shapes
  std::vector<Mode> out;
  for (Eigen::Index i = 0; i < es.eigenvalues().size() && out.size() < count; ++i) {
    Mode md;
    const double w2 = std::max(0.0, es.eigenvalues()(i));
    md.freq_hz = std::sqrt(w2) / (kTwoPi);
    md.shape = es.eigenvectors().col(i);
    const Eigen::Vector2d tcp(md.shape(tcp_x_), md.shape(tcp_x_ + 1));
    md.tcp_direction_rad = std::atan2(tcp.y(), tcp.x());
    md.tcp_modal_stiffness_n_per_m = tcp.squaredNorm() > 0.0 ? w2 / tcp.squaredNorm() : INFINITY;
    md.tcp_shape = tcp;
    const double stored = md.shape.dot(kr * md.shape);
    md.loss_factor = stored > 0.0 ? md.shape.dot(k_.imag() * md.shape) / stored : 0.0;
    out.push_back(std::move(md));
  }
  return out;
}

Eigen::Matrix2cd PlanarChain::tcp_frf_direct(double f_hz) const {
  const double w = kTwoPi * f_hz;
  const Eigen::MatrixXcd d = k_ - (w * w) * m_mass_.cast<Complex>();
  Eigen::MatrixXcd rhs = Eigen::MatrixXcd::Zero(d.rows(), 2);
  rhs(tcp_x_, 0) = 1.0, rhs(tcp_x_ + 1, 1) = 1.0;
  const Eigen::MatrixXcd x = d.partialPivLu().solve(rhs);
  Eigen::Matrix2cd g;
  g << x(tcp_x_, 0), x(tcp_x_, 1), x(tcp_x_ + 1, 0), x(tcp_x_ + 1, 1);
  return g;
}

Eigen::MatrixXcd PlanarChain::link_dynamic_stiffness(std::size_t i, double w) const {
  const Link& l = m_.links[i];
  const int nodes = l.elements + 1;
  Eigen::MatrixXcd d = Eigen::MatrixXcd::Zero(3 * nodes, 3 * nodes);
  const double le = l.length_m / l.elements;
  const ElementMatrices e = frame_element(le, l.mass_kg / l.length_m, l.bending_stiffness_nm2, l.axial_stiffness_n);
  const Eigen::Matrix<double, 6, 6> t = rotation(angles_[i]);
  const Eigen::Matrix<double, 6, 6> de = t.transpose() * (e.k - (w * w) * e.m) * t;
  for (int el = 0; el < l.elements; ++el) d.block(3 * el, 3 * el, 6, 6) += de.cast<Complex>();
  if (i + 1 == m_.links.size()) {  // the head at the TCP
    const int last = 3 * l.elements;
    d(last, last) -= w * w * m_.head_mass_kg;
    d(last + 1, last + 1) -= w * w * m_.head_mass_kg;
    d(last + 2, last + 2) -= w * w * m_.head_inertia_kgm2;
  }
  return d;
}

Eigen::Matrix2cd PlanarChain::tcp_frf_rcsa(double f_hz) const {
  const double w = kTwoPi * f_hz;
  Eigen::Matrix3cd g_end = Eigen::Matrix3cd::Zero();  // the assembly so far, at its free end (x, y, th)
  for (std::size_t i = 0; i < m_.links.size(); ++i) {
    // The link's free-free receptances at its two ends (s = start, e = end).
    const Eigen::MatrixXcd d = link_dynamic_stiffness(i, w);
    const Eigen::Index last = d.rows() - 3;
    Eigen::MatrixXcd unit = Eigen::MatrixXcd::Zero(d.rows(), 6);
    for (int c = 0; c < 3; ++c) unit(c, c) = 1.0, unit(last + c, 3 + c) = 1.0;
    const Eigen::MatrixXcd cols = d.partialPivLu().solve(unit);
    Eigen::Matrix<Complex, 6, 6> h;
    h.topRows(3) = cols.topRows(3);
    h.bottomRows(3) = cols.bottomRows(3);
    const Eigen::Matrix3cd hss = h.block(0, 0, 3, 3), hse = h.block(0, 3, 3, 3), hes = h.block(3, 0, 3, 3),
                           hee = h.block(3, 3, 3, 3);
    // The joint: rotation through the spring's compliance, translations rigid or through theirs. The
    // base is rigid (its receptance is zero); otherwise the assembly's end receptance adds to the link's start.
    Eigen::Matrix3cd c = Eigen::Matrix3cd::Zero();
    c(2, 2) = 1.0 / joint_stiffness(m_.joints[i]);
    if (!translation_rigid(m_.joints[i])) c(0, 0) = c(1, 1) = 1.0 / joint_translational_stiffness(m_.joints[i]);
    const Eigen::Matrix3cd sum = (i == 0 ? Eigen::Matrix3cd::Zero() : g_end) + hss + c;
    g_end = hee - hes * sum.partialPivLu().solve(hse);
  }
  return g_end.topLeftCorner<2, 2>();
}

}  // namespace robodamp::robot
