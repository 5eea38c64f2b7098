#include "identify/pose_fit_inputs.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "config/number_text.hpp"
#include "identify/modal_fit.hpp"
#include "identify/pose_measurements.hpp"

namespace robodamp::identify {

robot::MeasuredFrf read_measured_frf(const std::string& item) {
  const auto colon = item.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument("--measured = '" + item + "': expected Q1,Q2,...:FRF.csv (joint angles in deg)");
  robot::MeasuredFrf m;
  std::stringstream qs(item.substr(0, colon));
  for (std::string tok; std::getline(qs, tok, ',');) {
    double v = 0.0;
    if (auto p = config::parse_number("--measured", tok, {"deg", -360.0, 360.0}, false, v))
      throw std::invalid_argument(*p + " (in '" + item + "')");
    m.joints_deg.push_back(v);
  }
  m.name = item.substr(colon + 1);
  const FrfData d = read_frf_csv(m.name, FrfKind::kReceptance);
  m.freq_hz = d.f_hz;
  m.receptance_m_per_n = d.h;
  return m;
}

PoseFitInputs read_pose_fit_inputs(const std::vector<std::string>& measured,
                                   const std::vector<std::string>& measurement_dirs,
                                   const std::vector<std::string>& hold_out, const config::RobotModelConfig& model) {
  PoseFitInputs d;
  for (const auto& item : measured) d.fit.push_back(read_measured_frf(item));
  if (!measurement_dirs.empty()) {
    PoseMeasurements pm = read_pose_measurements(measurement_dirs);
    check_against_model(pm, model);
    d.direction = pm.direction;
    d.modes = pm.modes;
    for (auto& f : pm.frfs) d.fit.push_back(std::move(f));
  }
  for (const auto& name : hold_out) {
    const auto it = std::find_if(d.fit.begin(), d.fit.end(), [&](const auto& f) { return f.name == name; });
    if (it == d.fit.end()) throw std::invalid_argument("--hold-out '" + name + "': no measured pose of that name");
    d.held.push_back(std::move(*it));
    d.fit.erase(it);
  }
  return d;
}

}  // namespace robodamp::identify
