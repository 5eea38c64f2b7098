#include "tune/pose_tune.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "analysis/pose_schedule.hpp"
#include "tune/phase_start.hpp"

namespace robodamp::tune {

namespace {

std::string fmt(double v, const char* f = "%.4g") {
  char b[48];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// A mode's peak receptance along the axis (modal-stiffness form): 1 / (2 k zeta).
double peak_m_per_n(const config::ModeConfig& m) { return 1.0 / (2.0 * m.stiffness_n_per_m * m.damping_ratio); }

// Whether moving joint j over the box's width changes the plant: a mode's frequency by 1 %, or a mode's
// peak receptance by 5 % of the largest peak (a mode the axis barely sees may turn a lot and matter little).
bool joint_moves_modes(const PoseTuneInput& in, const config::PoseRegionConfig& r, std::size_t j) {
  const config::PoseScheduleConfig& s = *in.cell.pose_schedule;
  const std::vector<double> centre = analysis::region_centre(r);
  const analysis::PoseModes mid = analysis::pose_modes(in.model, centre, s.axis, s.modes);
  const double largest = peak_m_per_n(mid.modes[mid.dominant]);
  for (const double end : {r.min_deg[j], r.max_deg[j]}) {
    std::vector<double> q = centre;
    q[j] = end;
    const analysis::PoseModes at = analysis::pose_modes(in.model, q, s.axis, s.modes);
    if (at.modes.size() != mid.modes.size()) return true;
    for (std::size_t m = 0; m < at.modes.size(); ++m)
      if (std::abs(at.modes[m].natural_freq_hz / mid.modes[m].natural_freq_hz - 1.0) > 0.01 ||
          std::abs(peak_m_per_n(at.modes[m]) - peak_m_per_n(mid.modes[m])) > 0.05 * largest)
        return true;
  }
  return false;
}

// Which joints change the plant over the box (joint_moves_modes for each).
std::vector<bool> moving_joints(const PoseTuneInput& in, const config::PoseRegionConfig& r) {
  std::vector<bool> out(r.min_deg.size());
  for (std::size_t j = 0; j < out.size(); ++j) out[j] = joint_moves_modes(in, r, j);
  return out;
}

// The points^n grid over the box along the moving joints, the centre along the others; each pose once.
std::vector<NamedPose> grid_along(const config::PoseRegionConfig& r, const std::vector<bool>& moves, int points) {
  config::PoseRegionConfig grid = r;
  for (std::size_t j = 0; j < r.min_deg.size(); ++j)
    if (!moves[j]) grid.min_deg[j] = grid.max_deg[j] = 0.5 * (r.min_deg[j] + r.max_deg[j]);
  std::vector<NamedPose> out;
  for (auto& q : analysis::region_grid(grid, points)) {
    if (std::any_of(out.begin(), out.end(), [&](const NamedPose& p) { return p.joints_deg == q; })) continue;
    out.push_back({config::describe_pose(q), q});
  }
  return out;
}

}  // namespace

std::vector<NamedPose> mode_grid(const PoseTuneInput& in, const config::PoseRegionConfig& r, int points) {
  return grid_along(r, moving_joints(in, r), points);
}

namespace {

// The region's poses: its grid (see the header), a line every line_step_deg at most along each joint that
// moves the plant (the others at the centre: a wide region's set must hold between its grid's poses too),
// and every measured pose inside it.
std::vector<NamedPose> region_poses(const PoseTuneInput& in, const config::PoseRegionConfig& r, double line_step_deg) {
  const std::vector<bool> moves = moving_joints(in, r);
  std::vector<NamedPose> out = grid_along(r, moves, in.cell.pose_schedule->grid_points);
  const std::vector<double> centre = analysis::region_centre(r);
  for (std::size_t j = 0; j < r.min_deg.size(); ++j) {
    const double width = r.max_deg[j] - r.min_deg[j];
    const int steps = static_cast<int>(std::ceil(width / line_step_deg));
    if (steps < in.cell.pose_schedule->grid_points || !moves[j]) continue;
    for (int k = 0; k <= steps; ++k) {
      std::vector<double> q = centre;
      q[j] = r.min_deg[j] + width * k / steps;
      if (std::none_of(out.begin(), out.end(), [&](const NamedPose& p) { return p.joints_deg == q; }))
        out.push_back({config::describe_pose(q), q});
    }
  }
  for (const NamedPose& m : in.measured)
    if (config::region_holds(r, m.joints_deg.data(), m.joints_deg.size())) out.push_back(m);
  return out;
}

// The configuration a set is tuned from: the plant at the region's centre, the compensator pre-warped at
// the centre's dominant mode (the frequency the candidate's unit gain refers to).
config::Config region_base(const PoseTuneInput& in, const std::vector<double>& centre, double& match_hz) {
  const config::PoseScheduleConfig& s = *in.cell.pose_schedule;
  const analysis::PoseModes pm = analysis::pose_modes(in.model, centre, s.axis, s.modes);
  match_hz = pm.dominant_hz();
  config::Config base = analysis::config_at_pose(in.cell, pm);
  base.pose_schedule.reset();
  base.controller.match_freq_hz = match_hz;
  return base;
}

// The gain margin the tune asks for: the settings' and enough for supervision.max_gain_fraction (the
// schedule's own check refuses a set above that share of K_max at any pose of its region).
TuneSettings region_settings(const PoseTuneInput& in, const PoseTuneSettings& s) {
  TuneSettings t = s.tune;
  t.no_worse_mode = true;
  t.worse_mode_tolerance_pct = s.worse_mode_tolerance_pct;
  t.damping_window = false;
  t.worst_mode_objective = true;
  t.mode_band_min_hz = in.cell.pose_schedule->damping_band_min_hz;
  t.mode_band_max_hz = in.cell.pose_schedule->damping_band_max_hz;
  t.compensator_gain_max = s.compensator_gain_max;
  const double fraction = in.cell.supervision.max_gain_fraction;
  if (fraction > 0.0 && fraction < 1.0)
    t.gain_margin_min_db = std::max(t.gain_margin_min_db, -20.0 * std::log10(fraction) + 0.1);
  return t;
}

std::vector<const Evaluator*> pointers(const std::vector<Evaluator>& plants) {
  std::vector<const Evaluator*> out;
  for (const Evaluator& e : plants) out.push_back(&e);
  return out;
}

// The gains the phase-matched shape is tried at (tune/phase_start.hpp), N s/m.
constexpr double kPhaseMatchedGainsNsPerM[] = {100.0, 200.0, 500.0, 1000.0, 2000.0};

// Where the region's search starts: sets tuned at single poses (one plant each: cheap, with three times the
// evaluations) at the centre and at the poses with the region's lowest and highest dominant mode, the
// inherited set (if any), and the shape whose feedback opposes the velocity at every mode in the band at
// every pose of the region (tune/phase_start.hpp) at a few gains; each judged over every pose of the
// region; the best of them.
Candidate best_start(const PoseTuneInput& in, const config::Config& base, const std::vector<double>& centre,
                     const TunedRegion& region, const std::vector<Evaluator>& plants, const TuneSettings& t,
                     const std::optional<Candidate>& inherited) {
  const config::PoseScheduleConfig& sched = *in.cell.pose_schedule;
  std::vector<std::vector<double>> starts{centre};
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  std::vector<double> at_lo, at_hi;
  for (const NamedPose& p : region.poses) {
    const double f = analysis::pose_modes(in.model, p.joints_deg, sched.axis, sched.modes).dominant_hz();
    if (f < lo) lo = f, at_lo = p.joints_deg;
    if (f > hi) hi = f, at_hi = p.joints_deg;
  }
  for (const auto& q : {at_lo, at_hi})
    if (!q.empty() && std::find(starts.begin(), starts.end(), q) == starts.end()) starts.push_back(q);
  const std::vector<const Evaluator*> all = pointers(plants);
  TuneSettings single = t;
  single.global_evaluations *= 3, single.local_evaluations *= 3;
  std::optional<Evaluation> best;
  if (inherited) {
    best = evaluate_worst(all, *inherited);
    best->candidate = *inherited;
  }
  const auto contend = [&](const Candidate& c) {
    Evaluation e = evaluate_worst(all, c);
    e.candidate = c;
    if (!best || better(e, *best)) best = e;
  };
  for (const auto& q : starts) {
    const Evaluator one(analysis::config_at_pose(base, analysis::pose_modes(in.model, q, sched.axis, sched.modes)),
                        std::nullopt, single, config::describe_pose(q));
    contend(tune(std::vector<const Evaluator*>{&one}, single).best.candidate);
  }
  std::vector<config::Config> at_poses;
  for (const Evaluator& e : plants) at_poses.push_back(e.base());
  if (const auto matched = phase_matched(at_poses, t.mode_band_min_hz, t.mode_band_max_hz, t.compensator_gain_max))
    for (const double k_ns_per_m : kPhaseMatchedGainsNsPerM) {
      Candidate c = matched->shape;
      c.gain_ns_per_m = k_ns_per_m;
      contend(c);
    }
  return best->candidate;
}

// The plant at one of a region's poses: the region's base configuration with the model's modes there.
Evaluator region_plant(const PoseTuneInput& in, const config::Config& base, const TuneSettings& t, const NamedPose& p,
                       const analysis::PoseModes& modes) {
  config::Config at = analysis::config_at_pose(base, modes);
  at.source = in.cell.source + " at " + p.name;
  return Evaluator(at, std::nullopt, t, p.name);
}
Evaluator region_plant(const PoseTuneInput& in, const config::Config& base, const TuneSettings& t, const NamedPose& p) {
  const config::PoseScheduleConfig& sched = *in.cell.pose_schedule;
  return region_plant(in, base, t, p, analysis::pose_modes(in.model, p.joints_deg, sched.axis, sched.modes));
}

// How many times a region's search runs again with a pose its check found (checked_between).
constexpr int kCheckRounds = 2;

// The tuned set checked between the poses it was tuned at: the region's poses with half the line step, less
// those it was tuned at. Where it does not serve, the worst such pose joins the region's poses and the search
// runs again from the set (tune_from: never worse over them), at most kCheckRounds times. The result's worst
// case counts every checked pose, so the region serves only where the check holds too.
TuneResult checked_between(const PoseTuneInput& in, const config::Config& base, const TuneSettings& t,
                           const PoseTuneSettings& s, const PoseTuneProgress& progress, TunedRegion& out,
                           std::vector<Evaluator>& plants, TuneResult r) {
  std::vector<Evaluator> check;
  std::vector<NamedPose> check_poses;
  for (const NamedPose& p : region_poses(in, out.region, 0.5 * s.line_step_deg)) {
    if (std::any_of(out.poses.begin(), out.poses.end(),
                    [&](const NamedPose& q) { return q.joints_deg == p.joints_deg; }))
      continue;
    check.push_back(region_plant(in, base, t, p));
    check_poses.push_back(p);
  }
  std::vector<bool> joined(check.size(), false);  // moved into plants
  for (int round = 0; round < kCheckRounds; ++round) {
    std::optional<std::size_t> worst;
    double worst_violation = 0.0;
    for (std::size_t i = 0; i < check.size(); ++i) {
      if (joined[i]) continue;
      const Evaluation e = check[i](r.best.candidate);
      if (!e.feasible() && e.violation > worst_violation) worst = i, worst_violation = e.violation;
    }
    if (!worst) return r;
    if (progress)
      progress("  does not serve at " + check_poses[*worst].name + " between its poses: searched again with it");
    plants.push_back(std::move(check[*worst]));
    joined[*worst] = true;
    out.poses.push_back(check_poses[*worst]);
    r = tune_from(pointers(plants), r.best.candidate, t);
  }
  std::vector<const Evaluator*> all = pointers(plants);
  for (std::size_t i = 0; i < check.size(); ++i)
    if (!joined[i]) all.push_back(&check[i]);
  const Candidate c = r.best.candidate;
  r.best = evaluate_worst(all, c);
  r.best.candidate = c;
  return r;
}

}  // namespace

TunedRegion tune_region(const PoseTuneInput& in, const std::string& name, const std::vector<double>& min_deg,
                        const std::vector<double>& max_deg, const PoseTuneSettings& s, const PoseTuneProgress& progress,
                        const TunedRegion* parent) {
  const config::PoseScheduleConfig& sched = *in.cell.pose_schedule;
  TunedRegion out;
  out.region.name = name;
  out.region.min_deg = min_deg;
  out.region.max_deg = max_deg;
  out.poses = region_poses(in, out.region, s.line_step_deg);
  const std::vector<double> centre = analysis::region_centre(out.region);
  double match_hz = 0.0;
  const config::Config base = region_base(in, centre, match_hz);
  const TuneSettings t = region_settings(in, s);
  std::vector<Evaluator> plants;
  out.dominant_min_hz = std::numeric_limits<double>::infinity();
  for (const NamedPose& p : out.poses) {
    const analysis::PoseModes pm = analysis::pose_modes(in.model, p.joints_deg, sched.axis, sched.modes);
    out.dominant_min_hz = std::min(out.dominant_min_hz, pm.dominant_hz());
    out.dominant_max_hz = std::max(out.dominant_max_hz, pm.dominant_hz());
    plants.push_back(region_plant(in, base, t, p, pm));
  }
  if (progress)
    progress("region '" + name + "' " + config::describe_pose(min_deg) + " to " + config::describe_pose(max_deg) +
             ": " + std::to_string(out.poses.size()) + " poses, dominant mode " + fmt(out.dominant_min_hz) + "-" +
             fmt(out.dominant_max_hz) + " Hz");
  std::optional<Candidate> inherited;
  if (parent) inherited = restated(parent->worst.candidate, *parent->region.match_freq_hz, match_hz);
  const TuneResult r =
      checked_between(in, base, t, s, progress, out, plants,
                      tune_from(pointers(plants), best_start(in, base, centre, out, plants, t, inherited), t));
  out.worst = r.best;
  const Candidate& c = r.best.candidate;
  const config::Config tuned = with_candidate(base, c);
  for (const config::BlockConfig& b : tuned.controller.chain)
    if (b.kind == config::BlockKind::kCompensator)
      out.region.compensator = config::RegionCompensatorConfig{b.numerator, b.denominator};
  out.region.match_freq_hz = match_hz;
  out.region.gain_ns_per_m = c.gain_ns_per_m;
  out.region.polarity = c.polarity;
  if (progress)
    progress("  K " + fmt(c.gain_ns_per_m, "%.0f") + " N s/m, polarity " + std::to_string(c.polarity) +
             (out.serves() ? ", serves (worst mode " + fmt(out.worst.worst_mode_improvement_pct, "%+.1f") + " %)"
                           : ", does not serve: " + out.worst.binding));
  return out;
}

TunedRegion tune_robust(const PoseTuneInput& in, const PoseTuneSettings& s, const PoseTuneProgress& progress) {
  const config::PoseScheduleConfig& sched = *in.cell.pose_schedule;
  return tune_region(in, "workspace", sched.workspace_min_deg, sched.workspace_max_deg, s, progress);
}

namespace {

struct Cut {
  std::size_t joint{0};
  double at_deg{0.0};
};

// Where to cut a region (see the header): the joint whose travel over the box moves the dominant mode most
// (the other joints at the centre), among the joints wide enough to cut, at the angle where the dominant
// mode crosses the geometric mean of its range along it (kept min_width_deg from the ends); nothing when no
// joint is wide enough.
std::optional<Cut> cut_of(const PoseTuneInput& in, const TunedRegion& r, const PoseTuneSettings& s) {
  constexpr int kSteps = 32;
  const config::PoseScheduleConfig& sched = *in.cell.pose_schedule;
  const std::size_t n = r.region.min_deg.size();
  const std::vector<double> centre = analysis::region_centre(r.region);
  std::optional<Cut> best;
  double best_shift = -1.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double lo_deg = r.region.min_deg[j], width = r.region.max_deg[j] - lo_deg;
    if (width < 2.0 * s.min_width_deg) continue;
    std::vector<double> f(kSteps + 1);
    for (int k = 0; k <= kSteps; ++k) {
      std::vector<double> q = centre;
      q[j] = lo_deg + width * k / kSteps;
      f[k] = analysis::pose_modes(in.model, q, sched.axis, sched.modes).dominant_hz();
    }
    const auto [lo, hi] = std::minmax_element(f.begin(), f.end());
    const double shift = std::log(*hi / *lo) + 1e-6 * width;  // wider first when no joint moves the mode
    if (shift <= best_shift) continue;
    best_shift = shift;
    const double middle = std::sqrt(*lo * *hi);
    double at = lo_deg + 0.5 * width;
    for (int k = 0; k < kSteps; ++k)
      if ((f[k] - middle) * (f[k + 1] - middle) <= 0.0 && f[k] != f[k + 1]) {
        at = lo_deg + width * (k + (middle - f[k]) / (f[k + 1] - f[k])) / kSteps;
        break;
      }
    // Where the set stops serving, when that is known: halfway from the centre towards that pose.
    const auto binding =
        std::find_if(r.poses.begin(), r.poses.end(), [&](const NamedPose& p) { return p.name == r.worst.plant; });
    if (binding != r.poses.end() && std::abs(binding->joints_deg[j] - centre[j]) >= s.min_width_deg)
      at = 0.5 * (centre[j] + binding->joints_deg[j]);
    best = Cut{j, std::clamp(std::round(at * 2.0) / 2.0, lo_deg + s.min_width_deg,
                             lo_deg + width - s.min_width_deg)};  // 0.5 deg
  }
  return best;
}

}  // namespace

std::vector<TunedRegion> tune_schedule(const PoseTuneInput& in, const TunedRegion& robust, const PoseTuneSettings& s,
                                       const PoseTuneProgress& progress) {
  std::vector<TunedRegion> done, pending{robust};
  int count = 1;
  while (!pending.empty()) {
    TunedRegion r = std::move(pending.front());
    pending.erase(pending.begin());
    const std::optional<Cut> cut = r.serves() || count >= s.max_regions ? std::nullopt : cut_of(in, r, s);
    if (!cut) {
      done.push_back(std::move(r));
      continue;
    }
    const std::size_t j = cut->joint;
    const double mid = cut->at_deg;
    std::vector<double> lo_max = r.region.max_deg, hi_min = r.region.min_deg;
    lo_max[j] = std::min(r.region.max_deg[j], mid + 0.5 * s.overlap_deg);
    hi_min[j] = std::max(r.region.min_deg[j], mid - 0.5 * s.overlap_deg);
    if (progress)
      progress("cutting '" + r.region.name + "' across joint " + std::to_string(j + 1) + " at " + fmt(mid) + " deg");
    ++count;
    pending.push_back(tune_region(in, r.region.name + "a", r.region.min_deg, lo_max, s, progress, &r));
    pending.push_back(tune_region(in, r.region.name + "b", hi_min, r.region.max_deg, s, progress, &r));
  }
  // Named in joint order along the workspace: r1, r2, ...
  std::sort(done.begin(), done.end(),
            [](const TunedRegion& a, const TunedRegion& b) { return a.region.min_deg < b.region.min_deg; });
  for (std::size_t i = 0; i < done.size(); ++i) {
    std::string& name = done[i].region.name;
    name = done.size() == 1 ? "workspace" : "r";
    if (done.size() > 1) name += std::to_string(i + 1);  // (not "r" + to_string: GCC 12 warns falsely of -Wrestrict)
  }
  return done;
}

config::PoseScheduleConfig schedule_of(const config::PoseScheduleConfig& base,
                                       const std::vector<TunedRegion>& regions) {
  config::PoseScheduleConfig out = base;
  out.regions.clear();
  for (const TunedRegion& r : regions) out.regions.push_back(r.region);
  return out;
}

}  // namespace robodamp::tune
