// The candidate's compensator and its evaluation on one plant (the search over plants: tune/search.cpp).
#include "tune/compensator_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "analysis/impact_command.hpp"
#include "analysis/mode_improvement.hpp"
#include "analysis/task_pool.hpp"
#include "analysis/quiet_command.hpp"
#include "analysis/loop_model.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"
#include "modal/receptance.hpp"
#include "filters/polynomial.hpp"
#include "filters/transfer_function.hpp"
#include "units/units.hpp"

namespace robodamp::tune {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// a x b for polynomials with the highest power first (filters::Polynomial's product).
std::vector<double> multiply(const std::vector<double>& a, const std::vector<double>& b) {
  return (filters::Polynomial::from_descending(a) * filters::Polynomial::from_descending(b)).descending();
}

std::vector<double> second_order(double f_hz, double zeta) {
  const double w = kTwoPi * f_hz;
  return {1.0 / (w * w), 2.0 * zeta / w, 1.0};
}

std::vector<double> first_order(double f_hz) { return {1.0 / (kTwoPi * f_hz), 1.0}; }

// A rational compensator's N(s) / D(s), coefficients highest power first (continuous).
filters::TransferFunction rational(const std::vector<double>& num, const std::vector<double>& den) {
  return {filters::Polynomial::from_descending(num), filters::Polynomial::from_descending(den)};
}

// The candidate's compensator before its pre-warp: numerator and denominator.
std::pair<std::vector<double>, std::vector<double>> candidate_rational(const Candidate& c) {
  return {multiply(second_order(c.fz_hz, c.zeta_z), first_order(c.fa_hz)),
          multiply(second_order(c.fp_hz, c.zeta_p), first_order(c.fb_hz))};
}

const config::StructureConfig& job_structure(const config::MillingConfig& job) {
  const config::StructureConfig* st = job.find_structure(job.structure);
  if (st == nullptr) st = &job.structures.front();
  return *st;
}

// The largest closed-loop peak over the configured FRFs (discrete loop).
double closed_peak(const analysis::LoopModel& m, double gain, int polarity) {
  double peak = 0.0;
  for (const auto& f : analysis::improvements(m, gain, polarity, true)) peak = std::max(peak, f.closed_peak_m_per_n);
  return peak;
}

// The quiet cell's command RMS (analysis/quiet_command.hpp) may be at most this share of the supervisor's
// instability floor: at a third, a slow swell reaching twice the floor (what tripped a tuned loop on a
// quiet cell) is a 5-sigma event.
constexpr double kQuietShareOfFloor = 1.0 / 3.0;

// The largest |C(j w)| from 0.1 Hz to nyquist_hz over |C(match_hz)|.
double largest_gain_ratio(const filters::TransferFunction& c, double match_hz, double nyquist_hz) {
  const auto gain = [&](double f_hz) { return std::abs(c.at_hz(f_hz)); };
  double largest = 0.0;
  for (double f = 0.1; f <= nyquist_hz; f *= 1.05) largest = std::max(largest, gain(f));
  return largest / gain(match_hz);
}

// The same for the chain's compensator block (continuous; the block is pre-warped at the match frequency).
double compensator_gain_ratio(const config::Config& cfg) {
  const auto b = std::find_if(cfg.controller.chain.begin(), cfg.controller.chain.end(),
                              [](const config::BlockConfig& x) { return x.kind == config::BlockKind::kCompensator; });
  if (b == cfg.controller.chain.end() || b->model != config::CompensatorModel::kRational) return 0.0;
  return largest_gain_ratio(rational(b->numerator, b->denominator), cfg.controller.match_freq_hz.value_or(10.0),
                            0.5 * cfg.loop.rate_hz);
}

void add_violation(Evaluation& e, double amount, const char* what) {
  if (amount <= 0.0) return;
  if (amount > e.violation) e.binding = what;
  e.violation += amount;
}

}  // namespace

config::BlockConfig compensator_block(const Candidate& c, const config::BlockConfig& replaced, double unity_hz) {
  config::BlockConfig b = replaced;
  b.kind = config::BlockKind::kCompensator;
  b.model = config::CompensatorModel::kRational;
  std::tie(b.numerator, b.denominator) = candidate_rational(c);
  const double gain = std::abs(rational(b.numerator, b.denominator).at_hz(unity_hz));
  for (double& a : b.numerator) a /= gain;
  return b;
}

Candidate restated(const Candidate& c, double from_hz, double to_hz) {
  const auto [num, den] = candidate_rational(c);
  Candidate out = c;
  const filters::TransferFunction tf = rational(num, den);
  out.gain_ns_per_m = std::clamp(c.gain_ns_per_m * std::abs(tf.at_hz(to_hz)) / std::abs(tf.at_hz(from_hz)),
                                 kGainMinNsPerM, kGainMaxNsPerM);
  return out;
}

std::complex<double> compensator_response(const Candidate& c, double f_hz) {
  const auto [num, den] = candidate_rational(c);
  return rational(num, den).at_hz(f_hz);
}

double compensator_gain_ratio(const Candidate& c, double match_hz, double nyquist_hz) {
  const auto [num, den] = candidate_rational(c);
  return largest_gain_ratio(rational(num, den), match_hz, nyquist_hz);
}

namespace {

// A cubic's roots as the search's second-order pair (f, zeta) and first-order corner f: the pair is the complex
// pair, or of three real roots the two nearest each other.
std::optional<std::array<double, 3>> pair_and_corner(const std::vector<double>& descending) {
  if (descending.size() != 4 || descending.front() == 0.0) return std::nullopt;
  std::vector<std::complex<double>> r = filters::Polynomial::from_descending(descending).roots();
  if (r.size() != 3) return std::nullopt;
  for (const auto& x : r)
    if (!(x.real() < 0.0)) return std::nullopt;
  std::size_t lone = 0;  // the real root left over
  double closest = kInf;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& a = r[(i + 1) % 3];
    const auto& b = r[(i + 2) % 3];
    const bool conjugate = std::abs(a - std::conj(b)) <= 1e-9 * std::abs(a) && a.imag() != 0.0;
    const double d = conjugate ? -1.0 : std::abs(a - b);
    if (r[i].imag() == 0.0 && d < closest) closest = d, lone = i;
  }
  const auto& a = r[(lone + 1) % 3];
  const auto& b = r[(lone + 2) % 3];
  const double w = std::sqrt(std::abs(a * b));
  return std::array<double, 3>{w / kTwoPi, -(a + b).real() / (2.0 * w), -r[lone].real() / kTwoPi};
}

}  // namespace

std::optional<Candidate> candidate_of(const config::Config& cfg) {
  for (const auto& b : cfg.controller.chain) {
    if (b.kind != config::BlockKind::kCompensator) continue;
    if (b.model != config::CompensatorModel::kRational) return std::nullopt;
    const auto zeros = pair_and_corner(b.numerator), poles = pair_and_corner(b.denominator);
    if (!zeros || !poles) return std::nullopt;
    return Candidate{
        cfg.controller.gain_ns_per_m, (*zeros)[0], (*zeros)[1], (*poles)[0], (*poles)[1], (*zeros)[2], (*poles)[2],
        cfg.controller.polarity};
  }
  return std::nullopt;
}

double unity_gain_hz(const config::Config& cfg) {
  if (cfg.controller.match_freq_hz) return *cfg.controller.match_freq_hz;
  return modal::dominant_mode_hz(cfg.robot, cfg.actuator.location).value_or(10.0);
}

config::Config with_candidate(const config::Config& base, const Candidate& c) {
  config::Config cfg = base;
  auto it = std::find_if(cfg.controller.chain.begin(), cfg.controller.chain.end(),
                         [](const config::BlockConfig& b) { return b.kind == config::BlockKind::kCompensator; });
  if (it == cfg.controller.chain.end())
    throw config::ConfigError({config::Problem{
        base.source, {}, "controller.chain", "has no compensator block for robodamp tune to replace"}});
  *it = compensator_block(c, *it, unity_gain_hz(base));
  cfg.controller.gain_ns_per_m = c.gain_ns_per_m;
  cfg.controller.polarity = c.polarity;
  return cfg;
}

struct Evaluator::Impact {
  Impact(const analysis::LoopModel& plant, double peak_n, double duration_s) : command(plant, peak_n, duration_s) {}
  analysis::ImpactCommand command;
};

namespace {

constexpr std::size_t kCheckedMinima = 4;

// The lowest `count` local minima of a lobe curve: (rpm, mm), lowest first.
std::vector<std::pair<double, double>> lowest_minima(const milling::LobeDiagram& d, std::size_t count) {
  std::vector<std::pair<double, double>> out;
  const auto& c = d.curve;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double v = c[i].b_lim_mm;
    if (!std::isfinite(v)) continue;
    if ((i == 0 || v <= c[i - 1].b_lim_mm) && (i + 1 == c.size() || v <= c[i + 1].b_lim_mm))
      out.emplace_back(c[i].rpm, v);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  if (out.size() > count) out.resize(count);
  return out;
}

}  // namespace

Evaluator::~Evaluator() = default;
Evaluator::Evaluator(Evaluator&&) noexcept = default;

Evaluator::Evaluator(const config::Config& base, std::optional<config::MillingConfig> job, const TuneSettings& s,
                     std::string name)
    : base_(base), name_(name.empty() ? base.source : std::move(name)), job_(std::move(job)), s_(s) {
  (void)with_candidate(base_, {});  // a chain without a compensator is refused here
  base_model_ = std::make_shared<const analysis::LoopModel>(base_);
  const double impact_n = s_.impact_peak_n.value_or(base_.bench.impact_peak_n);
  if (impact_n > 0.0)
    impact_ = std::make_unique<Impact>(*base_model_, impact_n,
                                       s_.impact_duration_ms.value_or(base_.bench.impact_duration_ms) * 1e-3);
  if (!job_) return;
  const config::StructureConfig& st = job_structure(*job_);
  const bool damps =
      std::any_of(st.parts.begin(), st.parts.end(), [](const auto& p) { return p.controller.has_value(); });
  if (!damps)
    throw config::ConfigError({config::Problem{job_->source,
                                               {},
                                               "structures." + st.name,
                                               "has no damping location (a part with controller: {config, location, "
                                               "direction}): there is nothing for robodamp tune to tune against"}});
  // The open loop of this plant (not of the job's own controller file): each plant's floors are its own.
  const milling::Structure open(st, false, {base_model_, base_.controller.gain_ns_per_m, base_.controller.polarity});
  process_ = milling::chatter_process(job_->tool, job_->material, job_->cut);
  // The depth at the job's speed is promised by the sampled loop's semi-discretization: a speed it can step.
  if (auto p = milling::sampled_speed_problem(job_->cut.spindle_rpm, job_->tool.teeth, base_.loop.rate_hz))
    throw config::ConfigError({config::Problem{job_->source, {}, "cut.spindle_rpm", *p}});
  const milling::LobeDiagram d = milling::LobeModel(open, *process_, job_->lobes).diagram();
  open_min_mm_ = d.minimum.b_lim_mm;
  // The open loop's lobes by SDM on the job's SDM speeds: their lowest minima are where the damped limit is
  // checked against the open loop's, by the accurate method.
  {
    config::LobesConfig grid = job_->lobes;
    grid.points = job_->time_domain.sdm_points;
    const milling::LobeDiagram g = milling::LobeModel(open, *process_, grid).diagram();
    std::vector<double> rpm, mm;
    for (const auto& p : g.curve) rpm.push_back(p.rpm), mm.push_back(p.b_lim_mm);
    const std::vector<milling::SdmPoint> sdm = milling::AccurateStability(open, *job_).critical(rpm, mm);
    milling::LobeDiagram as_lobes;
    for (const auto& p : sdm) {
      as_lobes.curve.push_back({p.rpm, p.critical_depth_mm, p.chatter_hz, 0});
      open_curve_.emplace_back(p.rpm, p.critical_depth_mm);
    }
    for (const auto& [r, m] : lowest_minima(as_lobes, kCheckedMinima))
      open_sdm_min_rpm_.push_back(r), open_sdm_min_mm_.push_back(m);
  }
  // The open loop's lobe peaks (local maxima of the envelope), and the floor between each two.
  std::vector<std::size_t> peaks;
  const auto& c = d.curve;
  for (std::size_t i = 1; i + 1 < c.size(); ++i)
    if (std::isfinite(c[i].b_lim_mm) && c[i].b_lim_mm > c[i - 1].b_lim_mm && c[i].b_lim_mm >= c[i + 1].b_lim_mm)
      peaks.push_back(i);
  std::vector<std::size_t> edges{0};
  edges.insert(edges.end(), peaks.begin(), peaks.end());
  edges.push_back(c.size() - 1);
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    double floor = kInf, at = 0.0;
    for (std::size_t i = edges[k]; i <= edges[k + 1]; ++i)
      if (c[i].b_lim_mm < floor) floor = c[i].b_lim_mm, at = c[i].rpm;
    if (!std::isfinite(floor)) continue;
    intervals_.emplace_back(c[edges[k]].rpm, c[edges[k + 1]].rpm);
    floors_mm_.push_back(floor);
    floor_rpm_.push_back(at);
  }
}

namespace {

// A candidate whose compensator the chain cannot realise at the loop rate (its configuration refused).
Evaluation unrealisable(const Candidate& cand) {
  Evaluation e;
  add_violation(e, 100.0, "the chain cannot realise the compensator at the loop rate");
  e.objective = -kInf;
  e.candidate = cand;
  return e;
}

}  // namespace

Evaluation Evaluator::operator()(const Candidate& cand, bool constraints_only) const {
  Evaluation e;
  try {
    e = assess_model(candidate_model(cand), constraints_only || constraints_only_);
  } catch (const config::ConfigError&) {
    return unrealisable(cand);
  }
  e.candidate = cand;
  return e;
}

namespace {

// The loop's checks of one candidate, which do not depend on each other: on the cores there are, each task
// writing only its own result (the same as one after the other). An unstable loop gets its gain limit and
// margins only.
struct LoopChecks {
  std::optional<double> k_max;
  analysis::Margins margins;  // its gain margin from k_max
  std::vector<analysis::ModePhase> phases;
  std::optional<analysis::ModeImprovement> worst;
  std::optional<analysis::CommandPeak> peak;
  std::optional<double> quiet_rms_v;
};

LoopChecks check_loop(const analysis::LoopModel& m, double k, int polarity, bool stable, const TuneSettings& s,
                      analysis::ImpactCommand* impact, double floor_v) {
  LoopChecks c;
  std::vector<std::function<void()>> tasks{[&] {  // the margins' crossing gain starts the scan for K_max
    c.margins = analysis::margins(m, k, polarity, std::nullopt);
    c.k_max = analysis::max_stable_gain(m, polarity, c.margins.crossing_gain_ns_per_m);
  }};
  if (stable) {
    if (impact) tasks.emplace_back([&] { c.peak = impact->peak(m, k, polarity); });
    tasks.emplace_back([&] {
      c.phases = analysis::mode_phases(m, k, polarity);
      if (s.no_worse_mode || s.worst_mode_objective)
        c.worst =
            analysis::worst_mode(analysis::mode_improvements(m, k, polarity), s.mode_band_min_hz, s.mode_band_max_hz);
      if (floor_v > 0.0) c.quiet_rms_v = analysis::quiet_command(m, k, polarity).rms_v;
    });
  }
  analysis::run_tasks(tasks, analysis::task_threads(0));
  if (c.k_max) c.margins.gain_margin_db = analysis::gain_margin_db(*c.k_max, k);
  return c;
}

// The loop's constraints of a stable candidate, in the order the report names them: margins, the modes'
// window and peaks, the compensator's gain, the quiet cell's command, the actuator at the impact.
void add_loop_constraints(Evaluation& e, const LoopChecks& checks, const config::Config& cfg, const TuneSettings& s) {
  add_violation(e, (s.gain_margin_min_db - e.gain_margin_db) / s.gain_margin_min_db, "gain margin");
  add_violation(e, (s.phase_margin_min_deg - e.phase_margin_deg) / s.phase_margin_min_deg, "phase margin");
  add_violation(e, (s.delay_margin_min_ms - e.delay_margin_ms) / s.delay_margin_min_ms, "delay margin");
  for (const auto& mode : checks.phases)
    e.worst_mode_phase_deg = std::max(e.worst_mode_phase_deg, std::abs(mode.feedback_phase_deg));
  if (s.damping_window) add_violation(e, (e.worst_mode_phase_deg - 90.0) / 90.0, "a mode outside the damping window");
  if (s.no_worse_mode || s.worst_mode_objective) {
    e.worst_mode_improvement_pct = checks.worst ? checks.worst->improvement_pct : kInf;
    if (s.no_worse_mode)
      add_violation(e, -(e.worst_mode_improvement_pct + s.worse_mode_tolerance_pct) / 100.0,
                    "a mode's peak worse than open loop");
  }
  if (s.compensator_gain_max > 0.0) {
    e.compensator_gain_ratio = compensator_gain_ratio(cfg);
    add_violation(e, e.compensator_gain_ratio / s.compensator_gain_max - 1.0,
                  "the compensator's gain away from the match frequency");
  }
  if (checks.quiet_rms_v) {
    e.quiet_command_rms_v = *checks.quiet_rms_v;
    add_violation(e, e.quiet_command_rms_v / (kQuietShareOfFloor * cfg.supervision.instability_floor_v) - 1.0,
                  "the quiet cell's command against the instability detector's floor");
  }
  if (checks.peak) {
    const analysis::CommandPeak& p = *checks.peak;
    e.peak_command_v = p.voltage_v;
    e.peak_coil_force_n = p.coil_force_n;
    e.peak_slew_v_per_s = p.slew_v_per_s;
    e.actuator_use = std::max({p.coil_force_n / cfg.actuator.force_limit_n, p.voltage_v / cfg.amplifier.voltage_limit_v,
                               p.slew_v_per_s / cfg.amplifier.slew_rate_v_per_s});
    add_violation(e, e.actuator_use - 1.0, "the actuator's limits at the impact");
  }
}

}  // namespace

// Every constraint of one candidate in the order the report names them, then its objective: the loop's
// checks, then the job's depths (or, without a job, the closed-loop peak or the worst mode).
Evaluation Evaluator::assess(const config::Config& cfg, bool constraints_only) const {
  return assess_model(std::make_shared<const analysis::LoopModel>(cfg), constraints_only);
}

Evaluation Evaluator::assess_model(const std::shared_ptr<const analysis::LoopModel>& m, bool constraints_only) const {
  const config::Config& cfg = m->config();
  Evaluation e;
  e.candidate.gain_ns_per_m = cfg.controller.gain_ns_per_m;
  e.candidate.polarity = cfg.controller.polarity;
  const Candidate& cand = e.candidate;
  const double k = cand.gain_ns_per_m;
  e.stable = m->stable(k, cand.polarity);
  const LoopChecks checks = check_loop(*m, k, cand.polarity, e.stable, s_, impact_ ? &impact_->command : nullptr,
                                       cfg.supervision.instability_floor_v);
  const analysis::Margins& mg = checks.margins;
  e.k_max_ns_per_m = checks.k_max.value_or(kInf);
  e.gain_margin_db = mg.gain_margin_db.value_or(kInf);
  e.phase_margin_deg = mg.phase_margin_deg.value_or(180.0);
  e.delay_margin_ms = mg.delay_margin_ms.value_or(kInf);
  if (!e.stable) {
    add_violation(e, 10.0 + std::log10(k / std::max(1.0, e.k_max_ns_per_m)), "stability");
    e.objective = -kInf;
    return e;
  }
  add_loop_constraints(e, checks, cfg, s_);
  if (!constraints_only) score(e, m);
  return e;
}

Evaluation Evaluator::finish(Evaluation checked) const {
  // An unstable candidate, or one the chain cannot realise, has no objective; a constraints-only plant none.
  if (constraints_only_ || !checked.stable) return checked;
  try {
    score(checked, candidate_model(checked.candidate));
  } catch (const config::ConfigError&) {  // as operator() has it
    return unrealisable(checked.candidate);
  }
  return checked;
}

void Evaluator::score(Evaluation& e, const std::shared_ptr<const analysis::LoopModel>& m) const {
  if (job_) return score_on_job(e, m);
  e.peak_m_per_n = closed_peak(*m, e.candidate.gain_ns_per_m, e.candidate.polarity);
  e.objective = s_.worst_mode_objective ? e.worst_mode_improvement_pct / 100.0 : -std::log10(e.peak_m_per_n);
}

// The job's depths with the damped loop: the accurate limits at the job's speed and where the damped and
// the open lobes dip (the objective and the floors' constraints), the zero-order lobes as first guesses.
void Evaluator::score_on_job(Evaluation& e, const std::shared_ptr<const analysis::LoopModel>& m) const {
  const Candidate& cand = e.candidate;
  const milling::Structure damped(job_structure(*job_), true, {m, cand.gain_ns_per_m, cand.polarity});
  const milling::LobeModel lobes(damped, *process_, job_->lobes);
  const milling::LobeDiagram d = lobes.diagram();
  e.min_depth_mm = d.minimum.b_lim_mm;
  // The objective and the depth at the job's speed by the accurate method: the sampled loop's SDM at the
  // job's speed, at the damped zero-order lobes' lowest minima (where the damped lobes dip) and at the open
  // loop's SDM minima (where the open loop's floors are); the zero-order limits are only the first guesses.
  std::vector<double> speeds{job_->cut.spindle_rpm}, guesses{lobes.critical_depth_mm(job_->cut.spindle_rpm, 1e-3)};
  for (const auto& [rpm, mm] : lowest_minima(d, kCheckedMinima)) speeds.push_back(rpm), guesses.push_back(mm);
  for (std::size_t i = 0; i < open_sdm_min_rpm_.size(); ++i) {
    speeds.push_back(open_sdm_min_rpm_[i]);
    const auto z = lobes.limit_at(open_sdm_min_rpm_[i]);
    guesses.push_back(z ? z->b_lim_mm : 1.0);
  }
  const milling::AccurateStability truth(damped, *job_);
  const std::vector<milling::SdmPoint> acc = truth.critical(speeds, guesses, 0, 5e-3);
  e.depth_at_speed_mm = acc.front().critical_depth_mm;
  e.accurate_min_mm = kInf;
  for (const auto& p : acc)
    if (p.critical_depth_mm < e.accurate_min_mm) e.accurate_min_mm = p.critical_depth_mm, e.accurate_min_rpm = p.rpm;
  e.objective = e.accurate_min_mm;
  e.open_minima_ratio = kInf;
  const std::size_t first_open = speeds.size() - open_sdm_min_rpm_.size();
  for (std::size_t i = 0; i < open_sdm_min_rpm_.size(); ++i)
    e.open_minima_ratio = std::min(e.open_minima_ratio, acc[first_open + i].critical_depth_mm / open_sdm_min_mm_[i]);
  add_violation(e, 1.0 - e.open_minima_ratio, "a lobe minimum below the open loop's (sampled-loop SDM)");
  if (s_.depth_at_speed_min_mm > 0.0)
    add_violation(e, (s_.depth_at_speed_min_mm - e.depth_at_speed_mm) / s_.depth_at_speed_min_mm,
                  "the depth at the job's spindle speed");
  e.floor_ratio = kInf;
  for (std::size_t k2 = 0; k2 < intervals_.size(); ++k2) {
    double floor = kInf;
    for (const auto& p : d.curve)
      if (p.rpm >= intervals_[k2].first && p.rpm <= intervals_[k2].second) floor = std::min(floor, p.b_lim_mm);
    e.floors_mm.push_back(floor);
    e.floor_ratio = std::min(e.floor_ratio, floor / floors_mm_[k2]);
    // The damped curve is on the same speeds as the open one: the point at the open floor's speed.
    const auto at =
        std::find_if(d.curve.begin(), d.curve.end(), [&](const auto& p) { return p.rpm >= floor_rpm_[k2]; });
    e.at_open_minima_mm.push_back(at == d.curve.end() ? kInf : at->b_lim_mm);
  }
  add_violation(e, 1.0 - e.floor_ratio, "a lobe floor below the open loop's");
}

std::vector<std::pair<double, double>> Evaluator::damped_curve_mm(const config::Config& cfg) const {
  std::vector<std::pair<double, double>> out;
  if (!job_) return out;
  const auto m = std::make_shared<const analysis::LoopModel>(cfg);
  if (!m->stable(cfg.controller.gain_ns_per_m, cfg.controller.polarity)) return out;
  const milling::Structure damped(job_structure(*job_), true,
                                  {m, cfg.controller.gain_ns_per_m, cfg.controller.polarity});
  config::LobesConfig grid = job_->lobes;
  grid.points = job_->time_domain.sdm_points;
  const milling::AccurateStability truth(damped, *job_);
  std::vector<double> rpm, mm;
  for (const auto& p : milling::LobeModel(damped, *process_, grid).diagram().curve)
    if (p.rpm <= truth.max_rpm()) rpm.push_back(p.rpm), mm.push_back(p.b_lim_mm);
  for (const auto& p : truth.critical(rpm, mm)) out.emplace_back(p.rpm, p.critical_depth_mm);
  return out;
}

std::vector<ModeImprovement> Evaluator::mode_improvements(const config::Config& cfg) const {
  return analysis::mode_improvements(analysis::LoopModel(cfg), cfg.controller.gain_ns_per_m, cfg.controller.polarity);
}

}  // namespace robodamp::tune
