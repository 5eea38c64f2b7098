#include "tune/never_worse.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "analysis/pose_schedule.hpp"
#include "milling/live_stability.hpp"

namespace robodamp::tune {

namespace {

template <class... A>
std::string fmt(const char* f, A... a) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

struct Interval {
  double lo, hi;
};

// The joint the region is widest in.
std::size_t widest_joint(const config::PoseRegionConfig& r) {
  std::size_t j = 0;
  for (std::size_t i = 1; i < r.min_deg.size(); ++i)
    if (r.max_deg[i] - r.min_deg[i] > r.max_deg[j] - r.min_deg[j]) j = i;
  return j;
}

config::PoseRegionConfig piece(const config::PoseRegionConfig& r, std::size_t j, Interval along, std::string name,
                               bool off) {
  config::PoseRegionConfig p = r;
  p.name = std::move(name);
  p.min_deg[j] = along.lo, p.max_deg[j] = along.hi;
  if (off) p.gain_ns_per_m = 0.0;
  return p;
}

// One region's pieces: the set where it is not worse, K = 0 where it is (see the header).
void split_region(const config::PoseRegionConfig& r, double k,
                  const std::function<double(const std::vector<double>&)>& ratio,
                  const std::vector<std::vector<double>>& extra, double step, double rpm, NeverWorse& out) {
  const std::size_t j = widest_joint(r);
  std::vector<double> q = analysis::region_centre(r);
  std::vector<std::pair<double, double>> line;  // (joint j, damped / open)
  const int n = std::max(1, static_cast<int>(std::ceil((r.max_deg[j] - r.min_deg[j]) / step)));
  for (int i = 0; i <= n; ++i) {
    q[j] = r.min_deg[j] + (r.max_deg[j] - r.min_deg[j]) * i / n;
    line.emplace_back(q[j], ratio(q));
  }
  std::vector<Interval> off;  // runs of worse poses, two steps wider each side
  double worst = 1.0, worst_at = 0.0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (!(line[i].second < kNotWorse)) continue;
    if (line[i].second < worst) worst = line[i].second, worst_at = line[i].first;
    const Interval w{std::max(r.min_deg[j], line[i].first - 2.0 * step),
                     std::min(r.max_deg[j], line[i].first + 2.0 * step)};
    if (!off.empty() && w.lo <= off.back().hi)
      off.back().hi = w.hi;
    else
      off.push_back(w);
  }
  bool whole = false;
  std::string extra_note;
  for (const auto& p : extra) {
    if (!config::region_holds(r, p.data(), p.size())) continue;
    const double v = ratio(p);
    if (!(v < kNotWorse)) continue;
    const bool covered =
        std::any_of(off.begin(), off.end(), [&](const Interval& o) { return p[j] >= o.lo && p[j] <= o.hi; });
    if (!covered)
      whole = true, extra_note = fmt(" (%.1f %% at %s, off the line through its centre)", 100.0 * (1.0 - v),
                                     config::describe_pose(p).c_str());
    if (v < worst) worst = v, worst_at = p[j];
  }
  if (off.empty() && !whole) {
    out.regions.push_back(r);
    return;
  }
  // The set's pieces between the off runs, each reaching one step into its neighbours (checked not worse).
  std::vector<Interval> on;
  double from = r.min_deg[j];
  for (const Interval& o : off) {
    if (o.lo > from) on.push_back({from, std::min(r.max_deg[j], o.lo + step)});
    from = std::max(from, o.hi - step);
  }
  if (from < r.max_deg[j] && (off.empty() || off.back().hi < r.max_deg[j])) on.push_back({from, r.max_deg[j]});
  std::erase_if(on, [&](const Interval& i) { return i.hi - i.lo < 2.0 * step; });
  if (whole || on.empty()) {
    out.regions.push_back(piece(r, j, {r.min_deg[j], r.max_deg[j]}, r.name, true));
    out.notes.push_back(
        fmt("region '%s': its set (K %.0f N s/m) makes the job's cut at %.0f rpm up to %.1f %% shallower than the open "
            "loop (joint %zu = %.1f deg)%s: the damper off in the whole region (K = 0)",
            r.name.c_str(), k, rpm, 100.0 * (1.0 - worst), j + 1, worst_at, extra_note.c_str()));
    return;
  }
  std::string where;
  std::vector<config::PoseRegionConfig> pieces;
  for (std::size_t i = 0; i < off.size(); ++i) {
    pieces.push_back(piece(r, j, off[i], r.name + "_off" + std::to_string(i + 1), true));
    where += fmt("%s%.1f-%.1f", i ? ", " : "", off[i].lo, off[i].hi);
  }
  for (std::size_t i = 0; i < on.size(); ++i)
    pieces.push_back(piece(r, j, on[i], r.name + "_" + std::to_string(i + 1), false));
  // In the joint's order (the first region holding a pose runs it at arming: in an overlap, the lower one).
  std::stable_sort(pieces.begin(), pieces.end(),
                   [&](const auto& a, const auto& b) { return a.min_deg[j] < b.min_deg[j]; });
  out.regions.insert(out.regions.end(), pieces.begin(), pieces.end());
  out.notes.push_back(fmt(
      "region '%s': its set (K %.0f N s/m) makes the job's cut at %.0f rpm up to %.1f %% shallower than the open loop "
      "(joint %zu = %.1f deg): the damper off at joint %zu = %s deg, the set kept over the rest",
      r.name.c_str(), k, rpm, 100.0 * (1.0 - worst), j + 1, worst_at, j + 1, where.c_str()));
}

}  // namespace

NeverWorse never_worse_at_speed(const config::Config& cell, const config::MillingConfig& job, double rpm,
                                const std::vector<std::vector<double>>& extra_poses, double step_deg) {
  const analysis::PoseScheduleAnalysis sched = analysis::analyse_pose_schedule(cell);
  const config::PoseScheduleConfig& ps = *cell.pose_schedule;
  std::vector<config::Config> sets;
  for (const auto& rs : sched.regions) sets.push_back(rs.config);
  milling::LiveStability live(job, "", sets, {},
                              milling::PoseDynamics{ps.model_resolved, sched.model, ps.axis, ps.modes});
  NeverWorse out;
  for (std::size_t i = 0; i < ps.regions.size(); ++i) {
    const double k = sched.regions[i].gain_ns_per_m;
    if (k == 0.0) {
      out.regions.push_back(ps.regions[i]);
      continue;
    }
    // Against the open loop of the same plant (the loop's): the whole model's open limit differs from it by up to
    // LiveStabilitySettings::loop_model_tolerance, which no K makes up.
    const auto ratio = [&](const std::vector<double>& q) {
      const milling::LiveLimits l = live.compute(rpm, i, k, q);
      const double open = l.loop_open_mm > 0.0 ? l.loop_open_mm : l.open_mm;
      return open > 0.0 ? (l.damped_valid ? l.damped_mm : 0.0) / open : 1.0;
    };
    split_region(ps.regions[i], k, ratio, extra_poses, step_deg, rpm, out);
  }
  return out;
}

}  // namespace robodamp::tune
