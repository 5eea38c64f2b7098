#include "milling/cut_verdict.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "analysis/loop_model.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/forced_command.hpp"
#include "milling/lobes.hpp"
#include "milling/scheduled_lobes.hpp"
#include "milling/structure.hpp"

namespace robodamp::milling {

namespace {

CutCurve curve_of(const std::vector<SdmPoint>& pts, const std::vector<SdmPoint>& open, std::size_t n, double tol) {
  CutCurve c;
  c.min_mm = c.worst_ratio = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  std::size_t worse = 0, better = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double mm = pts[i].critical_depth_mm, ratio = mm / open[i].critical_depth_mm;
    c.mm.push_back(mm);
    if (mm < c.min_mm) c.min_mm = mm, c.min_rpm = pts[i].rpm;
    if (ratio < c.worst_ratio) c.worst_ratio = ratio, c.worst_rpm = pts[i].rpm;
    sum += ratio;
    worse += ratio < 1.0 - tol ? 1U : 0U;
    better += ratio > 1.0 + tol ? 1U : 0U;
  }
  c.mean_ratio = sum / static_cast<double>(n);
  c.worse_share = static_cast<double>(worse) / static_cast<double>(n);
  c.better_share = static_cast<double>(better) / static_cast<double>(n);
  if (pts.size() > n) c.at_job_mm = pts[n].critical_depth_mm;
  return c;
}

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace

CutVerdict cut_verdict(const config::Config& cell, const config::MillingConfig& job, int speeds) {
  const config::StructureConfig& sc = job.selected_structure();
  const auto model = std::make_shared<const analysis::LoopModel>(cell);
  const int pol = cell.controller.polarity;
  const double k = cell.controller.gain_ns_per_m;
  const Structure open(sc, false, {model, k, pol}), fixed(sc, true, {model, k, pol});
  const AccurateStability open_truth(open, job), fixed_truth(fixed, job);
  CutVerdict v;
  v.job = job.source;
  v.method = fixed_truth.method() + " (damped), " + open_truth.method() + " (open loop)";
  v.fixed_gain_ns_per_m = k;
  const int n = speeds > 0 ? speeds : job.time_domain.sdm_points;
  const double lo = job.lobes.rpm_min, hi = std::min(job.lobes.rpm_max, fixed_truth.max_rpm());
  std::set<double> grid;
  for (int i = 0; i < n; ++i) grid.insert(fixed_truth.stepped_rpm(lo + (hi - lo) * i / std::max(1, n - 1)));
  v.rpm.assign(grid.begin(), grid.end());
  std::vector<double> at = v.rpm;
  if (job.cut.spindle_rpm > 0.0 && job.cut.spindle_rpm <= fixed_truth.max_rpm())
    v.job_rpm = fixed_truth.stepped_rpm(job.cut.spindle_rpm), at.push_back(v.job_rpm);
  const LobeModel zoa(open, chatter_process(job.tool, job.material, job.cut), job.lobes);
  std::vector<double> guess;
  for (const double r : at) {
    const auto z = zoa.limit_at(r);
    guess.push_back(z && std::isfinite(z->b_lim_mm) ? z->b_lim_mm : job.cut.axial_mm);
  }
  const std::vector<SdmPoint> o = open_truth.critical(at, guess);
  std::vector<double> open_guess;
  for (const auto& p : o) open_guess.push_back(p.critical_depth_mm);
  std::vector<SdmPoint> f = fixed_truth.critical(at, open_guess);
  std::vector<double> fixed_mm;
  for (const auto& p : f) fixed_mm.push_back(p.critical_depth_mm);
  fixed_mm = holding_limits_mm(fixed, job, at, fixed_mm);  // as deep as the actuator follows the forced vibration
  for (std::size_t i = 0; i < f.size(); ++i) f[i].critical_depth_mm = fixed_mm[i];
  const std::size_t m = v.rpm.size();
  v.open = curve_of(o, o, m, v.tolerance);
  v.fixed = curve_of(f, o, m, v.tolerance);
  if (cell.controller.speed_schedule) {
    v.scheduled = curve_of(scheduled_limits(sc, job, cell, at, o), o, m, v.tolerance);
    v.bands = cell.controller.speed_schedule->bands.size();
  }
  return v;
}

std::string cut_verdict_line(const CutVerdict& v) {
  std::ostringstream o;
  const double tol_pct = 100.0 * v.tolerance;
  o << "VERDICT (the cut, " << v.method << "): ";
  const CutCurve& use = v.scheduled ? *v.scheduled : v.fixed;
  const std::string what =
      v.scheduled ? "the speed schedule" : fmt("the damper at K %.0f N s/m", v.fixed_gain_ns_per_m);
  if (v.job_rpm > 0.0)
    o << what
      << fmt(" gives %.3f mm at the job's %.1f rpm (%+.1f %% on the open loop's ", use.at_job_mm, v.job_rpm,
             100.0 * (use.at_job_mm / v.open.at_job_mm - 1.0))
      << fmt("%.3f mm); ", v.open.at_job_mm);
  o << (use.worse_share > 0.0 ? fmt("it is WORSE than no damper at %.0f %% of the %.0f speeds (down to x%.2f",
                                    100.0 * use.worse_share, static_cast<double>(v.rpm.size()), use.worst_ratio) +
                                    fmt(" at %.0f rpm)", use.worst_rpm)
                              : fmt("never worse than no damper (by %.1f %%) at the %.0f speeds", tol_pct,
                                    static_cast<double>(v.rpm.size())))
    << fmt(", deeper at %.0f %% of them; minimum %.3f mm", 100.0 * use.better_share, use.min_mm)
    << fmt(" (open loop %.3f mm)", v.open.min_mm);
  if (v.scheduled && v.job_rpm > 0.0 && v.fixed.at_job_mm < v.open.at_job_mm * (1.0 - v.tolerance))
    o << fmt(". Without the schedule, K %.0f N s/m would LOWER the limit at the job's speed by %.1f %%",
             v.fixed_gain_ns_per_m, 100.0 * (1.0 - v.fixed.at_job_mm / v.open.at_job_mm));
  return o.str();
}

std::string cut_verdict_text(const CutVerdict& v) {
  std::ostringstream o;
  o << "What the damper does for the cut (" << v.job << "; " << v.method << ", " << v.rpm.size() << " speeds over "
    << fmt("%.0f-%.0f rpm", v.rpm.front(), v.rpm.back()) << "):\n";
  char line[300];
  std::snprintf(line, sizeof line, "  %-28s %-22s %-30s %s\n", "", "open loop",
                fmt("fixed K %.0f N s/m", v.fixed_gain_ns_per_m).c_str(),
                v.scheduled ? ("speed schedule (" + std::to_string(v.bands) + " bands)").c_str() : "");
  o << line;
  auto row = [&](const std::string& label, const std::string& a, const std::string& b, const std::string& c) {
    std::snprintf(line, sizeof line, "  %-28s %-22s %-30s %s\n", label.c_str(), a.c_str(), b.c_str(), c.c_str());
    o << line;
  };
  auto at_job = [&](const CutCurve& c) {
    return fmt("%.3f mm (%+.1f %%)", c.at_job_mm, 100.0 * (c.at_job_mm / v.open.at_job_mm - 1.0));
  };
  if (v.job_rpm > 0.0)
    row(fmt("at the job's %.1f rpm", v.job_rpm), fmt("%.3f mm", v.open.at_job_mm), at_job(v.fixed),
        v.scheduled ? at_job(*v.scheduled) : "");
  auto minimum = [&](const CutCurve& c) { return fmt("%.3f mm at %.0f rpm", c.min_mm, c.min_rpm); };
  row("minimum", minimum(v.open), minimum(v.fixed), v.scheduled ? minimum(*v.scheduled) : "");
  row("mean over the speeds", "x1", fmt("x%.3f", v.fixed.mean_ratio),
      v.scheduled ? fmt("x%.3f", v.scheduled->mean_ratio) : "");
  auto worse = [&](const CutCurve& c) {
    return fmt("%.0f %%", 100.0 * c.worse_share) +
           (c.worse_share > 0.0 ? fmt(" (to x%.2f at %.0f rpm)", c.worst_ratio, c.worst_rpm) : "");
  };
  row(fmt("worse than open (> %.1f %%)", 100.0 * v.tolerance), "", worse(v.fixed),
      v.scheduled ? worse(*v.scheduled) : "");
  o << cut_verdict_line(v) << "\n";
  return o.str();
}

}  // namespace robodamp::milling
