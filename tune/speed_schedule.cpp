#include "tune/speed_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "config/number_range.hpp"
#include "control/controller.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/forced_command.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"
#include "tune/schedule_controllers.hpp"
#include "tune/schedule_in_time.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::tune {

namespace {

// Band edges to 0.01 rpm.
double edge(double a, double b) {
  const double m = std::round(50.0 * (a + b)) / 100.0;
  return m > a && m < b ? m : 0.5 * (a + b);
}

// The depths, computed once per (speed, candidate): candidate 0 the open loop, 1.. the damped ones; the
// fixed configuration (the cell as it is) is the last.
class Depths {
 public:
  Depths(const std::vector<ScheduleController>& controllers, const std::vector<ScheduleCandidate>& candidates,
         const config::Config& cell, const config::MillingConfig& job, const config::StructureConfig& structure,
         const ScheduleSettings& s)
      : job_(job), s_(s) {
    const auto& own = controllers.front();
    structures_.push_back(std::make_unique<milling::Structure>(
        structure, false, milling::Structure::LiveLoop{own.model, 0.0, own.polarity}));
    for (std::size_t i = 1; i < candidates.size(); ++i) {
      const auto& c = controllers[candidates[i].controller];
      structures_.push_back(std::make_unique<milling::Structure>(
          structure, true, milling::Structure::LiveLoop{c.model, candidates[i].gain_ns_per_m, c.polarity}));
    }
    structures_.push_back(std::make_unique<milling::Structure>(
        structure, true, milling::Structure::LiveLoop{own.model, cell.controller.gain_ns_per_m, own.polarity}));
    for (const auto& st : structures_) methods_.push_back(std::make_unique<milling::AccurateStability>(*st, job));
    config::LobesConfig lobes = job.lobes;
    preview_ = std::make_unique<milling::LobeModel>(*structures_.front(),
                                                    milling::chatter_process(job.tool, job.material, job.cut), lobes);
  }
  [[nodiscard]] std::size_t fixed() const { return methods_.size() - 1; }
  [[nodiscard]] const milling::AccurateStability& damped_method() const { return *methods_.back(); }
  [[nodiscard]] std::string method() const {
    return methods_.back()->method() + " (damped), " + methods_.front()->method() + " (open loop)";
  }

  // Computes what is missing for these speeds and candidates (the open loop first: it is the others' guess).
  void fill(const std::vector<double>& rpm, const std::vector<std::size_t>& which, const std::string& what) {
    std::vector<std::size_t> order = which;
    std::stable_sort(order.begin(), order.end(), [](std::size_t a, std::size_t b) { return a == 0 && b != 0; });
    std::size_t total = 0, done = 0;
    std::vector<std::vector<double>> todo(order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      for (double r : rpm)
        if (!cache_.count({r, order[k]})) todo[k].push_back(r);
    for (const auto& t : todo) total += t.size();
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (todo[k].empty()) continue;
      std::vector<double> guess;
      for (double r : todo[k]) guess.push_back(order[k] == 0 ? open_guess(r) : depth(r, 0));
      const auto pts = methods_[order[k]]->critical(todo[k], guess, s_.threads, 1e-3, [&](std::size_t n) {
        if (s_.progress) s_.progress(what, done + n, total);
      });
      done += todo[k].size();
      // A damped limit holds only as deep as the actuator follows the cut's forced vibration (milling/forced_command.hpp).
      std::vector<double> mm;
      for (const auto& p : pts) mm.push_back(p.critical_depth_mm);
      mm = milling::holding_limits_mm(*structures_[order[k]], job_, todo[k], mm, s_.threads);
      for (std::size_t i = 0; i < pts.size(); ++i) {
        cache_[{todo[k][i], order[k]}] = mm[i];
        if (order[k] != 0) ++damped_limits_, capped_ += mm[i] < pts[i].critical_depth_mm ? 1U : 0U;
      }
    }
  }
  [[nodiscard]] double depth(double rpm, std::size_t candidate) const { return cache_.at({rpm, candidate}); }
  [[nodiscard]] const milling::Structure& structure(std::size_t candidate) const { return *structures_[candidate]; }
  // Where the cut in time chattered below it (tune/schedule_in_time.hpp), the time domain's limit.
  void lower(double rpm, std::size_t candidate, double mm) {
    double& v = cache_.at({rpm, candidate});
    v = std::min(v, mm);
    lowered_[{rpm, candidate}] = v;
  }
  [[nodiscard]] std::optional<double> lowered(double rpm, std::size_t candidate) const {
    const auto it = lowered_.find({rpm, candidate});
    return it == lowered_.end() ? std::nullopt : std::optional(it->second);
  }
  // Damped limits computed, and of them those the actuator's force limit capped (milling/forced_command.hpp).
  [[nodiscard]] std::size_t damped_limits() const { return damped_limits_; }
  [[nodiscard]] std::size_t capped() const { return capped_; }

 private:
  double open_guess(double rpm) const {
    const auto p = preview_->limit_at(rpm);
    return p && std::isfinite(p->b_lim_mm) && p->b_lim_mm > 0.0 ? p->b_lim_mm : job_.cut.axial_mm;
  }
  const config::MillingConfig& job_;
  const ScheduleSettings& s_;
  std::vector<std::unique_ptr<milling::Structure>> structures_;
  std::vector<std::unique_ptr<milling::AccurateStability>> methods_;
  std::unique_ptr<milling::LobeModel> preview_;
  std::map<std::pair<double, std::size_t>, double> cache_;
  std::map<std::pair<double, std::size_t>, double> lowered_;
  std::size_t damped_limits_{0}, capped_{0};
};

struct Grid {
  std::vector<double> rpm;          // ascending, the grid speeds as the sampled loop runs them
  std::vector<std::size_t> choice;  // candidate per grid speed
};

// The deepest candidate at one grid speed: the open loop unless a damped one beats it by gain_min_pct; the
// previous speed's kept while within keep_within_pct of the best.
std::size_t choose(const Depths& d, double rpm, std::size_t n_candidates, std::optional<std::size_t> previous,
                   const ScheduleSettings& s) {
  const double open = d.depth(rpm, 0);
  std::size_t best = 0;
  double best_mm = open;
  for (std::size_t c = 1; c < n_candidates; ++c)
    if (d.depth(rpm, c) > best_mm) best = c, best_mm = d.depth(rpm, c);
  if (best != 0 && best_mm < open * (1.0 + 0.01 * s.gain_min_pct)) best = 0, best_mm = open;
  if (previous && *previous != best) {
    const double prev_mm = d.depth(rpm, *previous);
    const bool prev_ok = *previous == 0 || prev_mm >= open * (1.0 + 0.01 * s.gain_min_pct);
    if (prev_ok && prev_mm >= best_mm * (1.0 - 0.01 * s.keep_within_pct)) return *previous;
  }
  return best;
}

// The depth each grid speed's band vouches for: the limit in time where its candidate's chattered there.
std::vector<std::optional<double>> caps_of(const Grid& g, const Depths& d) {
  std::vector<std::optional<double>> caps(g.rpm.size());
  for (std::size_t i = 0; i < g.rpm.size(); ++i)
    if (g.choice[i] != 0) caps[i] = d.lowered(g.rpm[i], g.choice[i]);
  return caps;
}

// A band per run of equal choices, changing halfway between grid speeds; the first and last reach the range. A
// grid speed whose candidate's limit was lowered to the time domain's is a band of its own with that depth limit,
// so that the limit binds only about the speed where it was found.
std::vector<config::SpeedBandConfig> bands_of(const Grid& g, const std::vector<std::optional<double>>& caps,
                                              const std::vector<ScheduleCandidate>& cands, double lo, double hi) {
  std::vector<config::SpeedBandConfig> bands;
  for (std::size_t i = 0; i < g.rpm.size(); ++i) {
    const double from = i == 0 ? lo : edge(g.rpm[i - 1], g.rpm[i]);
    const double to = i + 1 == g.rpm.size() ? hi : edge(g.rpm[i], g.rpm[i + 1]);
    const ScheduleCandidate& c = cands[g.choice[i]];
    if (!bands.empty() && i > 0 && g.choice[i] == g.choice[i - 1] && !caps[i] && !caps[i - 1]) {
      bands.back().rpm_max = to;
      continue;
    }
    bands.push_back({from, to, static_cast<int>(c.controller), c.gain_ns_per_m, caps[i]});
  }
  // The open loop's bands run the controller before them (K = 0: the chain does not act), so that no hand-over
  // happens where nothing changes.
  for (std::size_t i = 1; i < bands.size(); ++i)
    if (bands[i].gain_ns_per_m == 0.0) bands[i].controller = bands[i - 1].controller;
  return bands;
}

// The grid speed whose band holds rpm, and the candidate the bands run there.
std::size_t grid_index_at(const Grid& g, double rpm) {
  std::size_t i = 0;
  while (i + 1 < g.rpm.size() && rpm >= edge(g.rpm[i], g.rpm[i + 1])) ++i;
  return i;
}
std::size_t candidate_at(const Grid& g, double rpm) { return g.choice[grid_index_at(g, rpm)]; }

// The limit the bands give at rpm: their candidate's, no deeper than the band's depth limit (as the cell
// publishes it: milling/scheduled_lobes.hpp, milling/live_stability.hpp).
double scheduled_at(const Grid& g, const Depths& d, double rpm) {
  const std::size_t i = grid_index_at(g, rpm), c = g.choice[i];
  const double mm = d.depth(rpm, c);
  const auto cap = c == 0 ? std::nullopt : d.lowered(g.rpm[i], c);
  return cap ? std::min(mm, *cap) : mm;
}

// Fewer bands than the controller holds: the run whose speeds lose least (to the open loop) when they take
// a neighbour's candidate takes it, the narrowest first among equals.
void fit_band_count(Grid& g, const Depths& d, const std::vector<ScheduleCandidate>& cands, double lo, double hi) {
  while (bands_of(g, caps_of(g, d), cands, lo, hi).size() > config::kMaxSpeedBands) {
    std::vector<std::pair<std::size_t, std::size_t>> runs;  // [first, last] grid index
    for (std::size_t i = 0; i < g.rpm.size(); ++i)
      if (i == 0 || g.choice[i] != g.choice[i - 1])
        runs.push_back({i, i});
      else
        runs.back().second = i;
    double best_loss = std::numeric_limits<double>::infinity(), best_width = std::numeric_limits<double>::infinity();
    std::size_t best_run = 0, best_to = 0;
    for (std::size_t r = 0; r < runs.size(); ++r)
      for (const std::size_t n : {r == 0 ? r : r - 1, r + 1 < runs.size() ? r + 1 : r}) {
        if (n == r) continue;
        const std::size_t to = g.choice[runs[n].first];
        double loss = 0.0;
        for (std::size_t i = runs[r].first; i <= runs[r].second; ++i)
          loss = std::max(loss, 1.0 - d.depth(g.rpm[i], to) / d.depth(g.rpm[i], 0));
        const double width = g.rpm[runs[r].second] - g.rpm[runs[r].first];
        if (loss < best_loss - 1e-12 || (loss <= best_loss + 1e-12 && width < best_width))
          best_loss = loss, best_width = width, best_run = r, best_to = to;
      }
    for (std::size_t i = runs[best_run].first; i <= runs[best_run].second; ++i) g.choice[i] = best_to;
  }
}

std::vector<std::size_t> every(std::size_t n) {
  std::vector<std::size_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

// Two speeds between each pair of grid speeds (a quarter and three quarters of the way), as the sampled loop
// runs them, not already known.
std::vector<double> checks_between(const Grid& g, const milling::AccurateStability& damped,
                                   const std::set<double>& known) {
  std::vector<double> out;
  for (std::size_t i = 0; i + 1 < g.rpm.size(); ++i)
    for (const double f : {0.25, 0.75}) {
      const double r = damped.stepped_rpm(g.rpm[i] + f * (g.rpm[i + 1] - g.rpm[i]));
      if (r > g.rpm[i] && r < g.rpm[i + 1] && !known.count(r)) out.push_back(r);
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// The depth of the schedule's candidate at every checked speed (computed where missing, per candidate).
void fill_scheduled(Depths& d, const Grid& g, const std::vector<double>& speeds) {
  std::map<std::size_t, std::vector<double>> by;
  for (double r : speeds) by[candidate_at(g, r)].push_back(r);
  for (const auto& [c, rs] : by) d.fill(rs, {c}, "checking the bands");
}

// Checks between the grid speeds; those where the bands are worse than the open loop join the grid (every
// candidate computed, chosen afresh), for refine_rounds rounds. Returns every speed checked.
std::set<double> refine(Grid& g, Depths& d, std::size_t n_cands, const milling::AccurateStability& damped,
                        const ScheduleSettings& s, std::size_t& refined) {
  std::set<double> checked;
  for (int round = 0; round <= s.refine_rounds; ++round) {
    std::set<double> known(g.rpm.begin(), g.rpm.end());
    known.insert(checked.begin(), checked.end());
    const std::vector<double> checks = checks_between(g, damped, known);
    if (checks.empty()) break;
    d.fill(checks, {0}, "checking the bands");
    fill_scheduled(d, g, checks);
    checked.insert(checks.begin(), checks.end());
    std::vector<double> worse;
    for (double r : checks)
      if (d.depth(r, candidate_at(g, r)) < d.depth(r, 0) * (1.0 - 0.01 * s.worse_tolerance_pct)) worse.push_back(r);
    if (worse.empty()) break;
    // The last round: what is still worse gets the open loop's band (K = 0: never worse), which only shrinks the
    // bands on either side, so every speed left to them stays a checked candidate's.
    const bool last = round == s.refine_rounds;
    if (!last) d.fill(worse, every(n_cands), "refining the bands");
    for (double r : worse) {
      const auto at = std::lower_bound(g.rpm.begin(), g.rpm.end(), r);
      const auto i = static_cast<std::size_t>(at - g.rpm.begin());
      const std::size_t c = last ? 0 : choose(d, r, n_cands, std::nullopt, s);
      g.rpm.insert(at, r);
      g.choice.insert(g.choice.begin() + static_cast<std::ptrdiff_t>(i), c);
      checked.erase(r);
      ++refined;
    }
    if (last) break;
  }
  return checked;
}

// Which speeds of the schedule need a candidate chosen afresh: those whose band's candidate chattered in time
// at 0.95 x its limit or is worse than the open loop. A candidate that chattered there keeps the time domain's
// limit (to the micrometre below) as its depth at that speed and competes again at it; where the bands then run
// it, that speed is a band of its own with the limit as its depth_limit_mm, which the cell's live limits, the
// lobes and the cut's verdict honour. Cuts in time only where the candidate damps, once per speed and depth.
class InTime {
 public:
  InTime(Depths& d, const config::MillingConfig& job, const ScheduleSettings& s) : d_(d), job_(job), s_(s) {}
  std::vector<double> to_choose_again(const Grid& g, const std::vector<double>& speeds) {
    fill_scheduled(d_, g, speeds);
    std::vector<LimitInTime> todo;
    std::vector<std::pair<double, std::size_t>> keys;
    for (double r : speeds) {
      const std::size_t c = candidate_at(g, r);
      if (c == 0) continue;
      if (const double mm = scheduled_at(g, d_, r); checked_depth(r, c) != mm) {
        todo.push_back({r, &d_.structure(c), mm});
        keys.emplace_back(r, c);
      }
    }
    if (s_.progress && !todo.empty()) s_.progress("the damped limits in time", 0, todo.size());
    const std::vector<LimitInTimeResult> res = limits_in_time(job_, todo, s_.threads);
    std::set<double> again;
    for (std::size_t i = 0; i < res.size(); ++i) {
      ++checks_;
      checked_[keys[i]] = todo[i].limit_mm;
      if (res[i].held) continue;
      const double held_mm = std::floor(res[i].limit_mm * 1000.0) / 1000.0;
      lowered_.push_back({keys[i].first, keys[i].second, todo[i].limit_mm, held_mm, false});
      d_.lower(keys[i].first, keys[i].second, held_mm);
      again.insert(keys[i].first);
    }
    for (double r : speeds)
      if (scheduled_at(g, d_, r) < d_.depth(r, 0) * (1.0 - 0.01 * s_.worse_tolerance_pct)) again.insert(r);
    return {again.begin(), again.end()};
  }
  [[nodiscard]] std::size_t checks() const { return checks_; }
  [[nodiscard]] const std::vector<LoweredLimit>& lowered() const { return lowered_; }

 private:
  double checked_depth(double rpm, std::size_t c) const {
    const auto it = checked_.find({rpm, c});
    return it == checked_.end() ? -1.0 : it->second;
  }
  Depths& d_;
  const config::MillingConfig& job_;
  const ScheduleSettings& s_;
  std::map<std::pair<double, std::size_t>, double> checked_;
  std::size_t checks_{0};
  std::vector<LoweredLimit> lowered_;
};

// The schedule's damped limits in time, for refine_rounds rounds: where a speed needs a candidate chosen
// afresh it joins the grid (every candidate computed there); after the last round, the open loop's (K = 0).
// Then the limits are checked once more, and what is lowered then is reported in the summary, never hidden.
void check_in_time(SpeedSchedule& out, Grid& g, std::set<double>& checked, Depths& d, const config::MillingConfig& job,
                   double job_rpm, double lo, double hi) {
  const ScheduleSettings& s = out.settings;
  InTime in_time(d, job, s);
  auto speeds = [&] {
    std::set<double> all(g.rpm.begin(), g.rpm.end());
    all.insert(checked.begin(), checked.end());
    if (job_rpm > 0.0) all.insert(job_rpm);
    return std::vector<double>(all.begin(), all.end());
  };
  const double tol = 1.0 - 0.01 * s.worse_tolerance_pct;
  auto place = [&](double r, std::size_t c) {  // r on the grid with candidate c
    const auto at = std::lower_bound(g.rpm.begin(), g.rpm.end(), r);
    const auto i = static_cast<std::size_t>(at - g.rpm.begin());
    if (at != g.rpm.end() && *at == r) {
      g.choice[i] = c;
      return;
    }
    g.rpm.insert(at, r);
    g.choice.insert(g.choice.begin() + static_cast<std::ptrdiff_t>(i), c);
    checked.erase(r);
    ++out.refined_speeds;
  };
  // refine_rounds rounds of choosing again among every candidate; then a speed keeps its band's candidate at
  // its limit in time (a band of its own), or the open loop's where that is worse; the cuts in time check what
  // that changed once more, and what they lower then is kept the same way without another check.
  for (int round = 0;; ++round) {
    const std::vector<double> again = in_time.to_choose_again(g, speeds());
    if (again.empty()) break;
    const bool choose_again = round < s.refine_rounds;
    if (choose_again) d.fill(again, every(out.candidates.size()), "choosing again after the cuts in time");
    for (double r : again) {
      std::size_t c = candidate_at(g, r);
      if (choose_again)
        c = choose(d, r, out.candidates.size(), std::nullopt, s);
      else if (d.depth(r, c) < d.depth(r, 0) * tol)
        c = 0;
      place(r, c);
    }
    fit_band_count(g, d, out.candidates, lo, hi);
    if (round > s.refine_rounds) break;
  }
  out.limits_in_time = in_time.checks();
  out.lowered_in_time = in_time.lowered().size();
  out.lowered = in_time.lowered();
  for (LoweredLimit& l : out.lowered) l.kept = candidate_at(g, l.rpm) == l.candidate;
}

void summarise(SpeedSchedule& out, const Depths& d, const config::MillingConfig& job, double job_rpm, const Grid& g) {
  ScheduleSummary& m = out.summary;
  const double tol = 1.0 - 0.01 * out.settings.worse_tolerance_pct, better = 1.0 + 0.01 * out.settings.gain_min_pct;
  m.open_min_mm = m.fixed_min_mm = m.scheduled_min_mm = std::numeric_limits<double>::infinity();
  m.fixed_worst_ratio = m.scheduled_worst_ratio = std::numeric_limits<double>::infinity();
  double fixed_sum = 0.0, sched_sum = 0.0;
  std::size_t fixed_worse = 0, sched_worse = 0, sched_better = 0;
  for (const ScheduleSpeed& p : out.speeds) {
    if (p.open_mm < m.open_min_mm) m.open_min_mm = p.open_mm, m.open_min_rpm = p.rpm;
    if (p.fixed_mm < m.fixed_min_mm) m.fixed_min_mm = p.fixed_mm, m.fixed_min_rpm = p.rpm;
    if (p.scheduled_mm < m.scheduled_min_mm) m.scheduled_min_mm = p.scheduled_mm, m.scheduled_min_rpm = p.rpm;
    const double rf = p.fixed_mm / p.open_mm, rs = p.scheduled_mm / p.open_mm;
    fixed_sum += rf, sched_sum += rs;
    if (rf < m.fixed_worst_ratio) m.fixed_worst_ratio = rf, m.fixed_worst_rpm = p.rpm;
    if (rs < m.scheduled_worst_ratio) m.scheduled_worst_ratio = rs, m.scheduled_worst_rpm = p.rpm;
    fixed_worse += rf < tol ? 1U : 0U;
    sched_worse += rs < tol ? 1U : 0U;
    sched_better += rs >= better ? 1U : 0U;
    m.grid_speeds += p.grid ? 1U : 0U;
  }
  const auto n = static_cast<double>(out.speeds.size());
  m.speeds = out.speeds.size();
  m.fixed_mean_ratio = fixed_sum / n;
  m.scheduled_mean_ratio = sched_sum / n;
  m.fixed_worse_share = static_cast<double>(fixed_worse) / n;
  m.scheduled_worse_share = static_cast<double>(sched_worse) / n;
  m.scheduled_better_share = static_cast<double>(sched_better) / n;
  if (job_rpm > 0.0) {
    m.job_rpm = job_rpm;
    m.job_open_mm = d.depth(job_rpm, 0);
    m.job_fixed_mm = d.depth(job_rpm, d.fixed());
    m.job_scheduled_mm = scheduled_at(g, d, job_rpm);
  }
  (void)job;
}

std::string describe(const ScheduleController& c) {
  return c.file.empty() ? "the configuration's own controller" : c.file;
}

}  // namespace

SpeedSchedule schedule_speeds(const config::Config& cell, const std::vector<NamedController>& other_controllers,
                              const config::MillingConfig& job, const config::StructureConfig& structure,
                              const ScheduleSettings& s) {
  SpeedSchedule out;
  out.settings = s;
  out.controllers = schedule_controllers(cell, other_controllers, s);
  out.candidates.push_back({0, 0.0});
  for (std::size_t c = 0; c < out.controllers.size(); ++c) {
    if (out.controllers[c].gains.empty())
      out.notes.push_back(describe(out.controllers[c]) + ": " + out.controllers[c].top_gain_reason + "; not used");
    for (double k : out.controllers[c].gains) out.candidates.push_back({c, k});
  }
  Depths d(out.controllers, out.candidates, cell, job, structure, s);
  out.method = d.method();
  const milling::AccurateStability& damped = d.damped_method();
  const int n = s.speeds > 0 ? s.speeds : job.time_domain.sdm_points;
  const double lo = job.lobes.rpm_min, hi = std::min(job.lobes.rpm_max, damped.max_rpm());
  if (hi < job.lobes.rpm_max)
    out.notes.push_back("above " + config::format_number(hi) +
                        " rpm the sampled loop has fewer than 10 ticks per tooth "
                        "period: the schedule stops there, and K there is controller.gain_ns_per_m");
  std::set<double> grid_rpm;
  for (int i = 0; i < n; ++i) grid_rpm.insert(damped.stepped_rpm(lo + (hi - lo) * i / std::max(1, n - 1)));
  Grid g;
  g.rpm.assign(grid_rpm.begin(), grid_rpm.end());
  std::vector<std::size_t> all = every(out.candidates.size());
  all.push_back(d.fixed());
  d.fill(g.rpm, all, "every candidate on the grid");
  for (std::size_t i = 0; i < g.rpm.size(); ++i)
    g.choice.push_back(
        choose(d, g.rpm[i], out.candidates.size(), i ? std::optional(g.choice[i - 1]) : std::nullopt, s));
  fit_band_count(g, d, out.candidates, lo, hi);
  std::set<double> checked = refine(g, d, out.candidates.size(), damped, s, out.refined_speeds);
  fit_band_count(g, d, out.candidates, lo, hi);
  const double job_rpm = job.cut.spindle_rpm > 0.0 && job.cut.spindle_rpm <= damped.max_rpm()
                             ? damped.stepped_rpm(job.cut.spindle_rpm)
                             : 0.0;
  if (job_rpm > 0.0) d.fill({job_rpm}, {0, d.fixed()}, "the job's speed");
  check_in_time(out, g, checked, d, job, job_rpm, lo, hi);

  std::vector<double> speeds(g.rpm.begin(), g.rpm.end());
  speeds.insert(speeds.end(), checked.begin(), checked.end());
  d.fill(speeds, {0, d.fixed()}, "checking the bands");
  fill_scheduled(d, g, job_rpm > 0.0 ? std::vector<double>{job_rpm} : std::vector<double>{});
  fill_scheduled(d, g, speeds);
  std::sort(speeds.begin(), speeds.end());
  out.bands = bands_of(g, caps_of(g, d), out.candidates, lo, hi);
  const std::set<double> on_grid(g.rpm.begin(), g.rpm.end());
  for (double r : speeds) {
    ScheduleSpeed p;
    p.rpm = r;
    p.ticks_per_tooth = static_cast<int>(std::lround(60.0 * cell.loop.rate_hz / (r * job.tool.teeth)));
    p.grid = on_grid.count(r) > 0;
    p.open_mm = d.depth(r, 0);
    p.fixed_mm = d.depth(r, d.fixed());
    p.candidate = candidate_at(g, r);
    p.scheduled_mm = scheduled_at(g, d, r);
    p.band = config::speed_band_of(out.bands, r).value_or(0);
    out.speeds.push_back(p);
  }
  summarise(out, d, job, job_rpm, g);
  out.damped_limits = d.damped_limits();
  out.capped_limits = d.capped();
  return out;
}

}  // namespace robodamp::tune
