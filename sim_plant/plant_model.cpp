#include "filters/transfer_function.hpp"
#include "modal/receptance.hpp"
#include "sim_plant/plant_model.hpp"
#include "units/units.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace robodamp::sim {

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}
}  // namespace

Complex FrfPath::receptance(double f_hz) const {
  const Complex s(0.0, kTwoPi * f_hz);
  Complex h(0.0);
  for (const auto& m : modes) h += modal::mode_receptance(m.a, m.b, m.damping_ratio, m.wn_rad_per_s, s);
  return h;
}

double FrfPath::static_compliance_m_per_n() const {
  double h = 0.0;
  for (const auto& m : modes) h += m.a / (m.wn_rad_per_s * m.wn_rad_per_s);
  return h;
}

Complex ActuatorModel::n_per_v(double f_hz) const {
  return filters::actuator_n_per_v(f_hz, constant_n_per_v, natural_freq_hz, damping_ratio, delay_s);
}

std::size_t PlantModel::index_of(int location_id) const {
  for (std::size_t i = 0; i < locations.size(); ++i)
    if (locations[i].id == location_id) return i;
  throw std::out_of_range("no robot location with id " + std::to_string(location_id));
}

const FrfPath* PlantModel::path(std::size_t response, std::size_t excitation) const {
  for (const auto& p : paths)
    if (p.response == response && p.excitation == excitation) return &p;
  return nullptr;
}

Complex PlantModel::receptance(std::size_t response, std::size_t excitation, double f_hz) const {
  const FrfPath* p = path(response, excitation);
  return p != nullptr ? p->receptance(f_hz) : Complex(0.0);
}

namespace {

using Problems = std::vector<config::Problem>;

// FRF paths in the physical frame: H_phys = axis_sign(response) * H_table; a driving point must have a
// positive static compliance.
void add_paths(const config::Config& cfg, PlantModel& m, Problems& problems) {
  for (std::size_t i = 0; i < cfg.robot.frfs.size(); ++i) {
    const auto& f = cfg.robot.frfs[i];
    FrfPath p;
    p.name = f.name;
    p.origin = "robot.frfs[" + std::to_string(i) + "]";
    p.response = m.index_of(f.response_location);
    p.excitation = m.index_of(f.excitation_location);
    const double sign = m.locations[p.response].axis_sign;
    for (const auto& mode : f.modes) {
      const modal::ModeNumerator n = modal::mode_numerator(mode);
      p.modes.push_back({kTwoPi * mode.natural_freq_hz, mode.damping_ratio, sign * n.a, sign * n.b});
    }
    const double h0 = p.static_compliance_m_per_n();
    if (p.response == p.excitation && !(h0 > 0.0))
      problems.push_back({cfg.source,
                          {},
                          p.origin,
                          "(" + p.name + ") is a driving-point FRF with static compliance " + num(h0) +
                              " m/N after axis_sign " + std::to_string(static_cast<int>(sign)) + " of location " +
                              std::to_string(f.response_location) +
                              ": a physical receptance needs > 0; check the location's axis_sign"});
    m.paths.push_back(std::move(p));
  }
}

// Reciprocity (Maxwell-Betti): H_gh = H_hg in the physical frame. A given pair must agree in sign; a
// missing one is taken from its reciprocal.
void add_reciprocals(const config::Config& cfg, PlantModel& m, Problems& problems) {
  const std::size_t given = m.paths.size();
  for (std::size_t i = 0; i < given; ++i) {
    const FrfPath& p = m.paths[i];
    if (p.response == p.excitation) continue;
    if (const FrfPath* q = m.path(p.excitation, p.response)) {
      if (p.static_compliance_m_per_n() * q->static_compliance_m_per_n() < 0.0)
        problems.push_back(
            {cfg.source,
             {},
             p.origin,
             "(" + p.name + ") and " + q->origin + " (" + q->name + ") have static compliances of opposite sign (" +
                 num(p.static_compliance_m_per_n()) + " and " + num(q->static_compliance_m_per_n()) +
                 " m/N) in the physical frame: reciprocity fails; check the axis_sign of both locations"});
      continue;
    }
    FrfPath r = p;
    std::swap(r.response, r.excitation);
    std::ostringstream name;  // (a stream: GCC 12 warns falsely on a chain of string +)
    name << 'H' << m.locations[r.response].id << m.locations[r.excitation].id << " (= " << p.name << ')';
    r.name = name.str();
    r.origin = "reciprocal of " + p.name;
    m.notes.push_back(r.name + ": not given, taken from " + p.name + " by reciprocity (physical frame)");
    m.paths.push_back(std::move(r));
  }
  for (const auto& p : m.paths)
    if (m.locations[p.response].axis_sign < 0 && p.origin.rfind("robot", 0) == 0)
      m.notes.push_back(p.name + ": tabulated response axis at location " + std::to_string(m.locations[p.response].id) +
                        " is reversed; physical FRF = -table");
}

// One state-space: actuator proof mass [p, p'] first, then [q, q'] per mode block. A mode block is one
// (excitation location, natural frequency, damping) triple: paths excited at the same location that
// share a mode share its block and differ only in their output weights (a, b), so the realisation has no
// repeated block (docs/simulation.md). The transfer functions are the same as with one block per path and
// mode.
void build_state_space(const config::ActuatorConfig& ac, PlantModel& m) {
  struct Block {
    std::size_t excitation;
    double wn, zeta;
  };
  const std::size_t act = m.actuator.location;
  std::vector<Block> blocks;
  std::vector<std::vector<std::size_t>> block_of(m.paths.size());  // [path][mode]
  for (std::size_t pi = 0; pi < m.paths.size(); ++pi)
    for (const auto& mode : m.paths[pi].modes) {
      std::size_t k = 0;
      while (k < blocks.size() && !(blocks[k].excitation == m.paths[pi].excitation &&
                                    blocks[k].wn == mode.wn_rad_per_s && blocks[k].zeta == mode.damping_ratio))
        ++k;
      if (k == blocks.size()) blocks.push_back({m.paths[pi].excitation, mode.wn_rad_per_s, mode.damping_ratio});
      block_of[pi].push_back(k);
    }
  const Eigen::Index n = static_cast<Eigen::Index>(2 + 2 * blocks.size());
  const Eigen::Index nl = static_cast<Eigen::Index>(m.locations.size());
  Matrix a = Matrix::Zero(n, n), b = Matrix::Zero(n, 1 + nl), cx = Matrix::Zero(nl, n);
  const double wa = kTwoPi * ac.natural_freq_hz, za = ac.damping_ratio, t = ac.constant_n_per_v;
  a(0, 1) = 1.0;
  a(1, 0) = -wa * wa;
  a(1, 1) = -2.0 * za * wa;
  b(1, 0) = 1.0;
  // Eq. 3 (filters::actuator_n_per_v) as states: F = T s^2 / (s^2 + 2 za wa s + wa^2) V = T (V - 2 za wa p' - wa^2 p).
  const Eigen::RowVector2d f_state(-t * wa * wa, -t * 2.0 * za * wa);
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Eigen::Index k = static_cast<Eigen::Index>(2 + 2 * i);
    a(k, k + 1) = 1.0;
    a(k + 1, k) = -blocks[i].wn * blocks[i].wn;
    a(k + 1, k + 1) = -2.0 * blocks[i].zeta * blocks[i].wn;
    b(k + 1, 1 + static_cast<Eigen::Index>(blocks[i].excitation)) = 1.0;
    if (blocks[i].excitation == act) {
      a.block(k + 1, 0, 1, 2) += f_state;
      b(k + 1, 0) += t;
    }
  }
  for (std::size_t pi = 0; pi < m.paths.size(); ++pi)
    for (std::size_t j = 0; j < m.paths[pi].modes.size(); ++j) {
      const Eigen::Index k = static_cast<Eigen::Index>(2 + 2 * block_of[pi][j]);
      const auto r = static_cast<Eigen::Index>(m.paths[pi].response);
      cx(r, k) += m.paths[pi].modes[j].a;
      cx(r, k + 1) += m.paths[pi].modes[j].b;
    }
  // Receptance is strictly proper; velocity and acceleration follow by differentiating along the held
  // input (u' = 0 between samples).
  const Matrix cv = cx * a, dv = cx * b, ca = cv * a, da = cv * b;
  m.ss.a = a;
  m.ss.b = b;
  m.ss.c = Matrix::Zero(3 * nl + 1, n);
  m.ss.d = Matrix::Zero(3 * nl + 1, 1 + nl);
  m.ss.c.topRows(nl) = cx;
  m.ss.c.middleRows(nl, nl) = cv;
  m.ss.d.middleRows(nl, nl) = dv;
  m.ss.c.middleRows(2 * nl, nl) = ca;
  m.ss.d.middleRows(2 * nl, nl) = da;
  m.ss.c.block(3 * nl, 0, 1, 2) = f_state;
  m.ss.d(3 * nl, 0) = t;
}

}  // namespace

PlantModel build_plant_model(const config::Config& cfg) {
  Problems problems;
  if (cfg.robot.frfs.empty()) {
    problems.push_back({cfg.source,
                        {},
                        "robot.frfs",
                        "missing: the simulated plant and the loop analysis need the robot's modal data"});
    throw config::ConfigError(config::located(problems, cfg.yaml_text));
  }
  PlantModel m;
  m.locations = cfg.robot.locations;
  m.voltage_limit_v = cfg.amplifier.voltage_limit_v;
  add_paths(cfg, m, problems);
  add_reciprocals(cfg, m, problems);
  const config::ActuatorConfig& ac = cfg.actuator;
  m.actuator = {ac.constant_n_per_v, ac.natural_freq_hz, ac.damping_ratio,
                ac.delay_s,          ac.force_limit_n,   m.index_of(ac.location)};
  const std::size_t act = m.actuator.location, sensor = m.index_of(cfg.sensor.location);
  if (m.path(act, act) == nullptr)
    problems.push_back({cfg.source,
                        {},
                        "robot.frfs",
                        "no driving-point FRF at the actuator location " + std::to_string(ac.location) +
                            ": the actuator's own receptance is needed to simulate and close the loop"});
  if (m.path(sensor, act) == nullptr)
    problems.push_back({cfg.source,
                        {},
                        "robot.frfs",
                        "no FRF from the actuator location " + std::to_string(ac.location) +
                            " to the sensor location " + std::to_string(cfg.sensor.location) +
                            " (nor its reciprocal): the loop cannot close"});
  if (!problems.empty()) throw config::ConfigError(config::located(problems, cfg.yaml_text));
  build_state_space(ac, m);
  return m;
}

}  // namespace robodamp::sim
