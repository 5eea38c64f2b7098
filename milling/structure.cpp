#include "modal/receptance.hpp"
#include "milling/structure.hpp"

#include "analysis/pose_schedule.hpp"
#include "robot/robot_model.hpp"
#include "units/units.hpp"

#include <cmath>
#include <sstream>

namespace robodamp::milling {

namespace {

void add_resonances(std::vector<Resonance>& out, const config::FrfConfig& frf) {
  for (const auto& m : frf.modes) out.push_back({m.natural_freq_hz, m.damping_ratio});
}

}  // namespace

config::StructureConfig robot_through_cell(const config::StructureConfig& s, int location, int axis,
                                           const std::string& source, int across_location) {
  config::StructureConfig st;
  st.name = "robot_at_pose";
  for (const auto& part : s.parts)
    if (!part.pose && !part.controller) st.parts.push_back(part);
  config::StructurePartConfig robot;
  robot.name = "robot";
  config::ControllerPartConfig c;
  c.config_path = source;
  c.location = location;
  c.direction = axis == 0 ? config::Axis::kX : config::Axis::kY;
  c.across_location = across_location;
  robot.controller = c;
  st.parts.push_back(robot);
  return st;
}

Structure::Structure(std::array<std::vector<config::ModeConfig>, 4> modes, std::string name) : name_(std::move(name)) {
  for (std::size_t k = 0; k < 4; ++k) {
    modal_[k].modes = std::move(modes[k]);
    add_resonances(resonances_, modal_[k]);
  }
}

Structure::Structure(const config::StructureConfig& cfg, bool damped) : name_(cfg.name), damped_(damped) {
  for (const auto& part : cfg.parts) {
    for (std::size_t k = 0; k < 4; ++k)
      modal_[k].modes.insert(modal_[k].modes.end(), part.modes[k].begin(), part.modes[k].end());
    if (part.pose) add_pose(part.name, *part.pose);
    if (!part.controller) continue;
    const auto& pc = *part.controller;
    auto model = std::make_shared<const analysis::LoopModel>(config::load_config_file(pc.config_path));
    const double gain = model->config().controller.gain_ns_per_m;
    const int polarity = model->config().controller.polarity;
    add_controller(part.name, pc.config_path, pc, std::move(model), gain, polarity);
  }
  for (const auto& f : modal_) add_resonances(resonances_, f);
}

Structure::Structure(const config::StructureConfig& cfg, bool damped, const LiveLoop& live)
    : name_(cfg.name), damped_(damped) {
  for (const auto& part : cfg.parts) {
    for (std::size_t k = 0; k < 4; ++k)
      modal_[k].modes.insert(modal_[k].modes.end(), part.modes[k].begin(), part.modes[k].end());
    if (part.pose) add_pose(part.name, *part.pose);
    if (part.controller)
      add_controller(part.name, live.model->config().source, *part.controller, live.model, live.gain_ns_per_m,
                     live.polarity);
  }
  for (const auto& f : modal_) add_resonances(resonances_, f);
}

void Structure::add_pose(const std::string& part, const config::PosePartConfig& pc) {
  const config::RobotModelConfig m = config::load_robot_model(pc.model_path);
  if (m.measured_modes) {
    add_mapped_pose(part, pc, m);
    return;
  }
  auto chain = std::make_shared<const robot::PlanarChain>(robot::at_pose(m, pc.joints_deg));
  double zeta = 1.0;
  for (const auto& j : m.joints) zeta = std::min(zeta, std::max(j.damping_ratio, 1e-3));
  for (const auto& md : chain->modes(6)) resonances_.push_back({md.freq_hz, zeta});  // where the grids refine
  std::ostringstream os;
  os << part << ": " << m.name << " (" << pc.model_path << ") at joints";
  for (double q : pc.joints_deg) os << ' ' << q;
  os << " deg";
  notes_.push_back(os.str());
  poses_.push_back(std::move(chain));
}

// A model with measured modes: the modes mapped to the pose (robot/modal_map.hpp) in the robot's plane
// (analysis::config_in_plane_at_pose), the model's lowest kPoseModesForCut with the map's corrections, as modal
// terms: along the measured axis (H11), across it (H22) and between (H21, both ways). A mode the measurements
// alone know moves the TCP along the measured axis only. The chain itself would be the model without what the
// measurements corrected.
void Structure::add_mapped_pose(const std::string& part, const config::PosePartConfig& pc,
                                const config::RobotModelConfig& m) {
  const int axis = m.measured_modes->axis, across = 1 - axis;
  const config::Config plane =
      analysis::config_in_plane_at_pose(config::Config{}, m, pc.joints_deg, axis, static_cast<int>(kPoseModesForCut));
  for (const config::FrfConfig& f : plane.robot.frfs) {
    const int r = f.response_location == 1 ? axis : across, e = f.excitation_location == 1 ? axis : across;
    for (const std::size_t k : {static_cast<std::size_t>(2 * r + e), static_cast<std::size_t>(2 * e + r)}) {
      modal_[k].modes.insert(modal_[k].modes.end(), f.modes.begin(), f.modes.end());
      if (r == e) break;
    }
  }
  std::ostringstream os;
  os << part << ": " << m.name << " (" << pc.model_path << ", its measured modes mapped) at joints";
  for (double q : pc.joints_deg) os << ' ' << q;
  os << " deg";
  notes_.push_back(os.str());
}

void Structure::add_controller(const std::string& part, const std::string& source,
                               const config::ControllerPartConfig& pc, std::shared_ptr<const analysis::LoopModel> model,
                               double gain_ns_per_m, int polarity) {
  ControllerPart c;
  c.location = model->plant().index_of(pc.location);
  c.direction = pc.direction == config::Axis::kX ? 0 : 1;
  if (pc.across_location > 0) c.across = model->plant().index_of(pc.across_location);
  c.gain_ns_per_m = gain_ns_per_m;
  c.polarity = polarity;
  for (const auto& f : model->config().robot.frfs) add_resonances(resonances_, f);
  resonances_.push_back({model->config().actuator.natural_freq_hz, model->config().actuator.damping_ratio});
  std::ostringstream os;
  os << part << ": location " << pc.location << " of " << source;
  if (damped_) {
    if (!model->stable(c.gain_ns_per_m, c.polarity))
      throw config::ConfigError(
          {config::Problem{source,
                           {},
                           "controller",
                           "the damping loop is unstable at K = " + std::to_string(c.gain_ns_per_m) +
                               " N s/m, polarity " + std::to_string(c.polarity) + ": no closed-loop FRF exists"}});
    // Closed-loop poles below Nyquist: where the damped FRF has its resonances.
    const double fs = model->loop_rate_hz();
    for (const auto& z : model->closed_loop_poles(c.gain_ns_per_m, c.polarity)) {
      if (std::abs(z) < 1e-12) continue;
      const std::complex<double> s = std::log(z) * fs;
      const double f = std::abs(s.imag()) / (kTwoPi);
      if (f > 0.5 && f < 0.5 * fs) resonances_.push_back({f, std::max(1e-4, -s.real() / std::abs(s))});
    }
    os << ", closed loop at K = " << c.gain_ns_per_m << " N s/m, polarity " << c.polarity << " (sampled controller at "
       << fs << " Hz)";
  } else {
    os << ", open loop";
  }
  notes_.push_back(os.str());
  c.model = std::move(model);
  controllers_.push_back(std::move(c));
}

bool Structure::has_controller() const { return !controllers_.empty(); }

std::vector<Structure::ControllerPath> Structure::controller_paths() const {
  std::vector<ControllerPath> out;
  for (const auto& c : controllers_) {
    if (const sim::FrfPath* p = c.model->plant().path(c.location, c.location))
      out.push_back({c.direction, c.direction, *p});
    if (!c.across) continue;
    const std::size_t o = 1 - c.direction;
    for (const auto& [g, h, dg, dh] :
         {std::tuple{*c.across, c.location, o, c.direction}, std::tuple{c.location, *c.across, c.direction, o},
          std::tuple{*c.across, *c.across, o, o}})
      if (const sim::FrfPath* p = c.model->plant().path(g, h)) out.push_back({dg, dh, *p});
  }
  return out;
}

Eigen::Matrix2cd Structure::frf(double f_hz) const {
  Eigen::Matrix2cd g;
  for (std::size_t k = 0; k < 4; ++k)
    g(static_cast<Eigen::Index>(k / 2), static_cast<Eigen::Index>(k % 2)) =
        modal_[k].modes.empty() ? Complex(0.0) : modal::frf_receptance(modal_[k], f_hz);
  for (const auto& p : poses_) g += p->tcp_frf_direct(f_hz);
  for (const auto& c : controllers_) {
    auto add = [&](std::size_t resp, std::size_t exc, std::size_t dr, std::size_t de) {
      g(static_cast<Eigen::Index>(dr), static_cast<Eigen::Index>(de)) +=
          damped_ ? c.model->closed_sampled(resp, exc, f_hz, c.gain_ns_per_m, c.polarity)
                  : c.model->open_continuous(resp, exc, f_hz);
    };
    add(c.location, c.location, c.direction, c.direction);
    if (!c.across) continue;
    const std::size_t o = 1 - c.direction;
    add(*c.across, c.location, o, c.direction), add(c.location, *c.across, c.direction, o),
        add(*c.across, *c.across, o, o);
  }
  return g;
}

Eigen::Matrix2cd Structure::frf_cutter(double f_hz, config::Axis feed_axis) const {
  const Eigen::Matrix2cd g = frf(f_hz);
  if (feed_axis == config::Axis::kX) return g;
  // Feed along +y: the cutter's x is the machine's y, its wall normal the machine's -x.
  Eigen::Matrix2cd c;
  c << g(1, 1), -g(1, 0), -g(0, 1), g(0, 0);
  return c;
}

}  // namespace robodamp::milling
