#include "hil/cutting_load.hpp"

#include <algorithm>
#include <cmath>

#include "config/milling_config.hpp"
#include "milling/cutting.hpp"

namespace robodamp::hil {

SpindleProfile::SpindleProfile(std::vector<SpindleChange> changes) : changes_(std::move(changes)) {
  std::stable_sort(changes_.begin(), changes_.end(), [](const auto& a, const auto& b) { return a.t0_s < b.t0_s; });
}

double SpindleProfile::rpm(double t_s) const {
  double rpm = 0.0;
  for (const auto& c : changes_) {
    if (t_s < c.t0_s) break;
    if (t_s >= c.t1_s || c.t1_s <= c.t0_s)
      rpm = c.rpm;
    else
      rpm += (c.rpm - rpm) * (t_s - c.t0_s) / (c.t1_s - c.t0_s);
  }
  return rpm;
}

CutLoad cut_load_from_job(const std::string& job_path, const sim::PlantModel& model, int harmonics) {
  const config::MillingConfig job = config::load_milling_config(job_path);
  const config::StructureConfig* s = job.find_structure(job.structure);
  if (s == nullptr && !job.structures.empty()) s = &job.structures.front();
  const config::ControllerPartConfig* part = nullptr;
  if (s != nullptr)
    for (const auto& p : s->parts)
      if (p.controller) part = &*p.controller;
  if (part == nullptr)
    throw config::ConfigError({config::Problem{
        job_path, {}, "structures", "the cut needs a part with a controller: where the tool is on the robot"}});
  const milling::Cutter cutter = milling::cutter_from(job.tool);
  const milling::CutConditions cc{job.cut.mode, job.cut.radial_mm, job.cut.axial_mm, job.cut.feed_per_tooth_mm};
  const milling::ForceSpectrum f = milling::force_spectrum(cutter, job.material, cc, job.sle.axial_slices, harmonics);
  // The plant models the controller part's direction; in the cutter frame the wall normal is y when the
  // feed is along that direction's other axis (docs/milling.md).
  const bool wall_normal = (part->direction == config::Axis::kY) == (job.cut.feed_axis == config::Axis::kX);
  const auto& along = wall_normal ? f.fy : f.fx;
  CutLoad out;
  out.job = job_path;
  out.location = model.index_of(part->location);
  out.teeth = job.tool.teeth;
  for (std::size_t k = 0; k < along.size(); ++k) out.harmonics_n.push_back(k == 0 ? along[0] : 2.0 * along[k]);
  return out;
}

CuttingLoad::CuttingLoad(sim::Plant& plant, std::optional<CutLoad> cut, SpindleProfile profile, int measured_harmonics,
                         double steady_s)
    : plant_(plant), cut_(std::move(cut)), profile_(std::move(profile)), steady_s_(steady_s) {
  lockin_.assign(static_cast<std::size_t>(measured_harmonics), {0.0, 0.0});
  if (cut_) {
    auto f = std::make_unique<sim::ToothPassingForce>(cut_->location, cut_->harmonics_n);
    force_ = f.get();
    plant_.add_excitation(std::move(f));
  }
}

double CuttingLoad::before_step(double t_s) noexcept {
  const double rpm = profile_.rpm(t_s);
  if (rpm != rpm_) steady_since_s_ = t_s;
  rpm_ = rpm;
  t_s_ = t_s;
  if (force_ != nullptr) {
    phase_start_ = force_->phase_rad();
    force_->set_tooth_hz(rpm_ * cut_->teeth / 60.0);
  }
  return rpm_;
}

void CuttingLoad::after_step(double applied_v, double dt_s) noexcept {
  const sim::PlantCounters& c = plant_.counters();
  const bool saturated = c.voltage_clipped != clipped_ || c.force_limited != limited_;
  clipped_ = c.voltage_clipped, limited_ = c.force_limited;
  if (force_ == nullptr || !(rpm_ > 0.0)) return;
  in_cut_s_ += dt_s;
  if (saturated) saturated_s_ += dt_s;
  if (t_s_ - steady_since_s_ < steady_s_) return;
  measured_s_ += dt_s;
  // The command held over the step, against the tooth phase at the step's middle.
  const double mid = phase_start_ + M_PI * force_->tooth_hz() * dt_s;
  for (std::size_t k = 0; k < lockin_.size(); ++k)
    lockin_[k] += applied_v * std::polar(1.0, -static_cast<double>(k + 1) * mid);
  ++lockin_n_;
}

CuttingReport CuttingLoad::report() const {
  CuttingReport r;
  r.cut = cut_.has_value();
  r.last_rpm = rpm_;
  if (!cut_) return r;
  r.job = cut_->job;
  r.teeth = cut_->teeth;
  r.in_cut_s = in_cut_s_;
  r.measured_s = measured_s_;
  r.saturated_in_cut_s = saturated_s_;
  for (std::size_t k = 1; k < cut_->harmonics_n.size(); ++k)
    r.force_harmonics_n.push_back(std::abs(cut_->harmonics_n[k]));
  for (const auto& l : lockin_)
    r.command_harmonics_v.push_back(lockin_n_ ? 2.0 * std::abs(l) / static_cast<double>(lockin_n_) : 0.0);
  return r;
}

nlohmann::json cutting_json(const CuttingReport& r) {
  if (!r.cut) return nullptr;
  return {{"job", r.job},
          {"teeth", r.teeth},
          {"in_cut_s", r.in_cut_s},
          {"measured_s", r.measured_s},
          {"saturated_in_cut_s", r.saturated_in_cut_s},
          {"force_harmonics_n", r.force_harmonics_n},
          {"command_harmonics_v", r.command_harmonics_v},
          {"last_rpm", r.last_rpm}};
}

}  // namespace robodamp::hil
