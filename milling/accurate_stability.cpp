#include "milling/accurate_stability.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <mutex>

#include "analysis/task_pool.hpp"

namespace robodamp::milling {

AccurateStability::AccurateStability(const Structure& structure, const config::MillingConfig& job)
    : AccurateStability(structure, job, job.cut) {}

AccurateStability::AccurateStability(const Structure& structure, const config::MillingConfig& job,
                                     const config::CutConfig& cut)
    : grid_(job.time_domain.sdm_steps_per_period), teeth_(job.tool.teeth) {
  const Cutter cutter = cutter_from(job.tool);
  if (structure.damped() && structure.has_controller()) {
    method_ = "sampled-loop SDM";
    SampledSdmSettings s;
    s.axial_slices = job.time_domain.axial_slices;
    s.min_grid_per_period = job.time_domain.sdm_steps_per_period;
    sampled_ = std::make_unique<SampledSdm>(structure, cutter, job.material, cut.mode, cut.radial_mm, cut.feed_axis, s);
  } else {
    method_ = "SDM";
    open_ = std::make_unique<SdmModel>(cutter_modal_terms(structure, cut.feed_axis), cutter, job.material, cut.mode,
                                       cut.radial_mm, job.time_domain.axial_slices, job.time_domain.sdm_steps_per_period);
  }
}

double AccurateStability::max_rpm() const {
  return sampled_ ? sampled_->max_rpm() : std::numeric_limits<double>::infinity();
}

std::optional<std::string> AccurateStability::speed_problem(double rpm) const {
  if (sampled_) return sampled_speed_problem(rpm, teeth_, sampled_->loop_rate_hz());
  if (!(rpm > 0.0) || !std::isfinite(rpm)) return "spindle speed = " + std::to_string(rpm) + " rpm: must be > 0 and finite";
  return std::nullopt;
}

SdmPoint AccurateStability::critical(double rpm, double guess_mm, double rel_tol) const {
  const double guess = std::isfinite(guess_mm) && guess_mm > 0.0 ? guess_mm : 1.0;
  return sampled_ ? sampled_->critical(rpm, guess, rel_tol) : open_->critical(rpm, guess, rel_tol);
}

std::vector<SdmPoint> AccurateStability::critical(const std::vector<double>& rpm, const std::vector<double>& guess_mm,
                                                  std::size_t threads, double rel_tol,
                                                  const std::function<void(std::size_t)>& progress) const {
  std::vector<SdmPoint> out(rpm.size());
  std::vector<std::function<void()>> tasks;
  tasks.reserve(rpm.size());
  std::mutex m;
  std::size_t done = 0;
  for (std::size_t i = 0; i < rpm.size(); ++i)
    tasks.emplace_back([&, i] {
      out[i] = critical(rpm[i], i < guess_mm.size() ? guess_mm[i] : 1.0, rel_tol);
      if (progress) {
        const std::lock_guard<std::mutex> lock(m);
        progress(++done);
      }
    });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  return out;
}

std::complex<double> AccurateStability::multiplier(double axial_mm, double rpm) const {
  return sampled_ ? sampled_->multiplier(axial_mm, rpm) : open_->multiplier(axial_mm, rpm);
}

}  // namespace robodamp::milling
