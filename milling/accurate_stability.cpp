#include "milling/accurate_stability.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <utility>

#include "analysis/task_pool.hpp"
#include "milling/lobes.hpp"

namespace robodamp::milling {

namespace {

constexpr double kProbeStep = 1.2;   // between probed depths
constexpr double kMaxProbeMm = 1e3;  // the depth searches' ceiling (milling/sdm.hpp)
constexpr double kPeakLnMu = -0.69;  // a peak of ln|mu| below ln(0.5) is not searched for a window
constexpr int kPeakIterations = 12;  // golden-section steps: the peak's bracket from 44 % to 0.1 % of its depth
constexpr int kNeighbourRounds = 8;
// A diagram's runs of neighbouring speeds, and the first bracketing step from a guess a neighbour corrected.
constexpr std::size_t kDiagramRun = 10;
constexpr double kNeighbourStep = 1.1;

// A local peak of g = ln|mu| among probes lo < mid < hi (g(mid) the highest of the three): golden-section
// search for its top in log depth, returning the first depth found unstable (g >= 0), or nothing.
std::optional<double> unstable_at_peak(const std::function<double(double)>& g, double lo, double mid, double g_mid,
                                       double hi) {
  constexpr double kGolden = 0.3819660112501051;
  double a = std::log(lo), b = std::log(mid), c = std::log(hi), gb = g_mid;
  for (int i = 0; i < kPeakIterations; ++i) {
    const bool right = c - b > b - a;
    const double x = right ? b + kGolden * (c - b) : b - kGolden * (b - a);
    const double gx = g(std::exp(x));
    if (gx >= 0.0) return std::exp(x);
    if (gx > gb) {
      (right ? a : c) = b;
      b = x, gb = gx;
    } else {
      (right ? c : a) = x;
    }
  }
  return std::nullopt;
}

}  // namespace

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
  // The zero-order method's lowest limit at any chatter frequency (its lobes' floor at any speed; a lobe's
  // depth at a frequency is the same on every lobe): one pass over its frequency grid, no diagram.
  double zoa_min_mm = std::numeric_limits<double>::infinity();
  for (const LobePoint& p :
       LobeModel(structure, chatter_process(job.tool, job.material, cut), job.lobes).lobe_points(0))
    zoa_min_mm = std::min(zoa_min_mm, p.b_lim_mm);
  floor_mm_ = std::isfinite(zoa_min_mm) && zoa_min_mm > 0.0 ? 0.5 * zoa_min_mm : 1e-3;
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

class AccurateStability::Speed {
 public:
  Speed(const AccurateStability& a, double rpm) : open_(a.open_.get()), rpm_(rpm) {
    if (a.sampled_) sampled_.emplace(a.sampled_->at(rpm));
  }
  [[nodiscard]] double ln_mu(double axial_mm) {
    return std::log(std::abs(sampled_ ? sampled_->multiplier(axial_mm) : open_->multiplier(axial_mm, rpm_)));
  }
  [[nodiscard]] SdmPoint critical(double guess_mm, double rel_tol, double first_step) {
    return sampled_ ? sampled_->critical(guess_mm, rel_tol, first_step)
                    : open_->critical(rpm_, guess_mm, rel_tol, first_step);
  }

 private:
  const SdmModel* open_;
  std::optional<SampledSdm::AtSpeed> sampled_;
  double rpm_;
};

SdmPoint AccurateStability::search(Speed& at, double guess_mm, double rel_tol, double first_step) const {
  const bool usable = std::isfinite(guess_mm) && guess_mm > 0.0;
  return at.critical(usable ? guess_mm : 1.0, rel_tol, usable ? first_step : kBracketStep);
}

std::optional<double> AccurateStability::first_unstable(Speed& at, double from_mm, double to_mm) {
  const auto g = [&](double b) { return at.ln_mu(b); };
  double b0 = 0.0, g0 = 0.0, b1 = 0.0, g1 = 0.0;  // the two probes before this one
  int probes = 0;
  for (double b = from_mm; b < to_mm; b *= kProbeStep, ++probes) {
    const double gb = g(b);
    if (gb >= 0.0) return b;
    if (probes >= 2 && g1 > kPeakLnMu && g1 > g0 && g1 > gb)
      if (const auto u = unstable_at_peak(g, b0, b1, g1, b)) return u;
    b0 = b1, g0 = g1, b1 = b, g1 = gb;
  }
  return std::nullopt;
}

SdmPoint AccurateStability::below(Speed& at, const SdmPoint& p, double from_mm, double rel_tol) const {
  const double to = std::isfinite(p.critical_depth_mm) ? p.critical_depth_mm : kMaxProbeMm;
  if (!(from_mm < to)) return p;
  const std::optional<double> u = first_unstable(at, from_mm, to);
  return u ? search(at, *u, rel_tol) : p;
}

SdmPoint AccurateStability::critical(double rpm, double guess_mm, double rel_tol) const {
  Speed at(*this, rpm);
  return below(at, search(at, guess_mm, rel_tol), floor_mm_, rel_tol);
}

std::vector<SdmPoint> AccurateStability::critical(const std::vector<double>& rpm, const std::vector<double>& guess_mm,
                                                  std::size_t threads, double rel_tol,
                                                  const std::function<void(std::size_t)>& progress) const {
  const bool diagram = rpm.size() >= 3 && std::is_sorted(rpm.begin(), rpm.end());
  std::vector<SdmPoint> out(rpm.size());
  std::vector<std::function<void()>> tasks;
  tasks.reserve(rpm.size());
  std::mutex m;
  std::size_t done = 0;
  for (std::size_t i = 0; i < rpm.size(); ++i)
    tasks.emplace_back([&, i] {
      const double guess = i < guess_mm.size() ? guess_mm[i] : 1.0;
      if (diagram) {
        Speed at(*this, rpm[i]);
        out[i] = search(at, guess, rel_tol);
      } else {
        out[i] = critical(rpm[i], guess, rel_tol);
      }
      if (progress) {
        const std::lock_guard<std::mutex> lock(m);
        progress(++done);
      }
    });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  if (diagram) below_neighbours(rpm, out, threads, rel_tol);
  return out;
}

std::vector<SdmPoint> AccurateStability::diagram(const std::vector<double>& rpm, const std::vector<double>& guess_mm,
                                                 std::size_t threads, double rel_tol,
                                                 const std::function<void(std::size_t)>& progress) const {
  if (rpm.size() < 3 || !std::is_sorted(rpm.begin(), rpm.end()))
    return critical(rpm, guess_mm, threads, rel_tol, progress);
  std::vector<SdmPoint> out(rpm.size());
  std::mutex m;
  std::size_t done = 0;
  std::vector<std::function<void()>> tasks;
  for (std::size_t first = 0; first < rpm.size(); first += kDiagramRun)
    tasks.emplace_back([&, first] {
      double ratio = 0.0;  // the speed before's answer over its guess
      for (std::size_t i = first; i < std::min(rpm.size(), first + kDiagramRun); ++i) {
        const double guess = i < guess_mm.size() ? guess_mm[i] : 1.0;
        Speed at(*this, rpm[i]);
        // A guess that is not a positive finite depth gives no ratio, and search() starts from 1 mm without it.
        out[i] = ratio > 0.0 && std::isfinite(ratio) ? search(at, guess * ratio, rel_tol, kNeighbourStep)
                                                     : search(at, guess, rel_tol);
        ratio = out[i].critical_depth_mm / guess;
        if (progress) {
          const std::lock_guard<std::mutex> lock(m);
          progress(++done);
        }
      }
    });
  analysis::run_tasks(tasks, analysis::task_threads(threads));
  below_neighbours(rpm, out, threads, rel_tol);
  return out;
}

void AccurateStability::below_neighbours(const std::vector<double>& rpm, std::vector<SdmPoint>& out,
                                         std::size_t threads, double rel_tol) const {
  std::vector<std::size_t> check(out.size());
  for (std::size_t i = 0; i < check.size(); ++i) check[i] = i;
  for (int round = 0; round < kNeighbourRounds && !check.empty(); ++round) {
    std::vector<std::pair<std::size_t, double>> todo;  // speed, the neighbour's depth to probe from
    for (const std::size_t i : check) {
      double from = std::numeric_limits<double>::infinity();
      for (const std::size_t j : {i - 1, i + 1})  // i - 1 wraps to SIZE_MAX at 0: out of range
        if (j < out.size() && out[j].critical_depth_mm * (1.0 + 4.0 * rel_tol) < out[i].critical_depth_mm)
          from = std::min(from, out[j].critical_depth_mm);
      if (std::isfinite(from)) todo.emplace_back(i, from);
    }
    std::vector<SdmPoint> next(todo.size());
    std::vector<std::function<void()>> tasks;
    tasks.reserve(todo.size());
    for (std::size_t k = 0; k < todo.size(); ++k)
      tasks.emplace_back([&, k] {
        const auto [i, from] = todo[k];
        Speed at(*this, rpm[i]);
        next[k] = below(at, out[i], from, rel_tol);
      });
    analysis::run_tasks(tasks, analysis::task_threads(threads));
    check.clear();
    for (std::size_t k = 0; k < todo.size(); ++k) {
      const std::size_t i = todo[k].first;
      if (!(next[k].critical_depth_mm < out[i].critical_depth_mm)) continue;
      out[i] = next[k];
      if (i > 0) check.push_back(i - 1);
      if (i + 1 < out.size()) check.push_back(i + 1);
    }
    std::sort(check.begin(), check.end());
    check.erase(std::unique(check.begin(), check.end()), check.end());
  }
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
  d.curve = truth.diagram(speeds, guesses, threads, 1e-3, [&](std::size_t done) {
    if (progress) progress(done, speeds.size());
  });
  d.minimum.critical_depth_mm = std::numeric_limits<double>::infinity();
  for (const SdmPoint& p : d.curve)
    if (p.critical_depth_mm < d.minimum.critical_depth_mm) d.minimum = p;
  return d;
}

}  // namespace robodamp::milling
