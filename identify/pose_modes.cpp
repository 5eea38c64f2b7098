#include "identify/pose_modes.hpp"

#include <algorithm>
#include <stdexcept>

#include "identify/modal_fit.hpp"

namespace robodamp::identify {

namespace {

config::MeasuredPoseModes identify_one(const robot::MeasuredFrf& f, const PoseMeasurements& pm, const std::string& dir,
                                       double& error_pct) {
  FrfData d;
  d.f_hz = f.freq_hz;
  d.h = f.receptance_m_per_n;
  ModalFitSettings s;
  s.band_lo_hz = pm.band_min_hz, s.band_hi_hz = pm.band_max_hz;
  ModalFit fit;
  try {
    fit = fit_modes(d, s);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("pose '" + f.name + "' (" + dir + "): no mode identified: " + e.what());
  }
  error_pct = fit.fit_error_pct;
  config::MeasuredPoseModes p;
  p.name = f.name;
  p.joints_deg = f.joints_deg;
  for (const IdentifiedMode& m : fit.modes) {
    if (!(m.stiffness_n_per_m > 0.0) || !(m.damping_ratio > 0.0)) continue;  // not a real, damped mode
    p.modes.push_back(config::stiffness_mode(m.natural_freq_hz, m.damping_ratio, m.stiffness_n_per_m));
  }
  std::sort(p.modes.begin(), p.modes.end(),
            [](const auto& a, const auto& b) { return a.natural_freq_hz < b.natural_freq_hz; });
  if (p.modes.empty())
    throw std::invalid_argument("pose '" + f.name + "' (" + dir + "): no real mode with damping identified");
  return p;
}

}  // namespace

PoseModesIdentified identify_pose_modes(const PoseMeasurements& pm, const std::vector<std::string>& hold_out) {
  if (pm.direction == robot::FrfDirection::kXY)
    throw std::invalid_argument(
        "the measurements are a cross receptance (xy): the modes are identified on a driving point");
  for (const auto& name : hold_out)
    if (std::none_of(pm.frfs.begin(), pm.frfs.end(), [&](const auto& f) { return f.name == name; }))
      throw std::invalid_argument("--hold-out '" + name + "': no measured pose of that name");
  PoseModesIdentified out;
  out.measured.axis = pm.direction == robot::FrfDirection::kXX ? 0 : 1;
  std::vector<double> held_errors;
  for (std::size_t i = 0; i < pm.frfs.size(); ++i) {
    const bool held = std::find(hold_out.begin(), hold_out.end(), pm.frfs[i].name) != hold_out.end();
    double error = 0.0;
    config::MeasuredPoseModes p = identify_one(pm.frfs[i], pm, i < pm.dirs.size() ? pm.dirs[i] : "", error);
    (held ? out.held_out : out.measured.poses).push_back(std::move(p));
    (held ? held_errors : out.fit_error_pct).push_back(error);
  }
  if (out.measured.poses.empty())
    throw std::invalid_argument("every measured pose is held out: keep at least one in the map");
  out.fit_error_pct.insert(out.fit_error_pct.end(), held_errors.begin(), held_errors.end());
  return out;
}

}  // namespace robodamp::identify
