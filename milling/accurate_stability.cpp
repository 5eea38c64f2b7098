#include "milling/accurate_stability.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <mutex>

#include "analysis/task_pool.hpp"
#include "milling/lobes.hpp"

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
    open_ =
        std::make_unique<SdmModel>(cutter_modal_terms(structure, cut.feed_axis), cutter, job.material, cut.mode,
                                   cut.radial_mm, job.time_domain.axial_slices, job.time_domain.sdm_steps_per_period);
  }
}

double AccurateStability::max_rpm() const {
  return sampled_ ? sampled_->max_rpm() : std::numeric_limits<double>::infinity();
}

std::optional<std::string> AccurateStability::speed_problem(double rpm) const {
  if (sampled_) return sampled_speed_problem(rpm, teeth_, sampled_->loop_rate_hz());
  if (!(rpm > 0.0) || !std::isfinite(rpm))
    return "spindle speed = " + std::to_string(rpm) + " rpm: must be > 0 and finite";
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

std::vector<bool> AccurateStability::stable(double axial_mm, const std::vector<double>& rpm,
                                            std::size_t threads) const {
  std::vector<char> out(rpm.size(), 0);  // not vector<bool>: the tasks write their own elements
  std::vector<std::function<void()>> tasks;
  tasks.reserve(rpm.size());
  for (std::size_t i = 0; i < rpm.size(); ++i)
    tasks.emplace_back([&, i] { out[i] = stable(axial_mm, rpm[i]) ? 1 : 0; });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  return {out.begin(), out.end()};
}

AccurateDiagram accurate_diagram(const Structure& structure, const config::MillingConfig& job, std::size_t threads,
                                 const std::function<void(std::size_t done, std::size_t of)>& progress) {
  const AccurateStability truth(structure, job);
  config::LobesConfig grid = job.lobes;
  grid.points = job.time_domain.sdm_points;
  const LobeDiagram guess = LobeModel(structure, chatter_process(job.tool, job.material, job.cut), grid).diagram();
  std::vector<double> speeds, guesses;
  for (const auto& p : guess.curve)
    if (p.rpm <= truth.max_rpm()) speeds.push_back(p.rpm), guesses.push_back(p.b_lim_mm);
  AccurateDiagram d;
  d.method = truth.method();
  d.grid_per_period = truth.grid_per_period();
  d.speeds_left_out = guess.curve.size() - speeds.size();
  d.max_rpm = truth.max_rpm();
  d.curve = truth.critical(speeds, guesses, threads, 1e-3, [&](std::size_t done) {
    if (progress) progress(done, speeds.size());
  });
  d.minimum.critical_depth_mm = std::numeric_limits<double>::infinity();
  for (const SdmPoint& p : d.curve)
    if (p.critical_depth_mm < d.minimum.critical_depth_mm) d.minimum = p;
  return d;
}

}  // namespace robodamp::milling
