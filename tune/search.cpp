// The search over candidates (tune/compensator_search.hpp): the worst plant's evaluation, and NLopt's seeded
// global search then the local polish, per polarity and restart.
#include "tune/compensator_search.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace robodamp::tune {

bool better(const Evaluation& a, const Evaluation& b) {
  if (a.feasible() != b.feasible()) return a.feasible();
  if (!a.feasible()) return a.violation < b.violation;
  return a.objective > b.objective;
}

Evaluation evaluate_worst(const std::vector<const Evaluator*>& plants, const Candidate& c,
                          bool skip_infeasible_objective) {
  std::vector<Evaluation> per;
  if (skip_infeasible_objective) {
    for (const Evaluator* p : plants) {
      per.push_back((*p)(c, true));
      per.back().plant = p->name();
    }
    // Every plant's constraints hold: each plant's objective, from where its constraints left it.
    if (std::none_of(per.begin(), per.end(), [](const Evaluation& e) { return e.violation > 0.0; }))
      for (std::size_t i = 0; i < per.size(); ++i) {
        per[i] = plants[i]->finish(std::move(per[i]));
        per[i].plant = plants[i]->name();
      }
  }
  if (per.empty())
    for (const Evaluator* p : plants) {
      per.push_back((*p)(c));
      per.back().plant = p->name();
    }
  if (per.size() == 1) return per.front();
  // The worst: the most violating plant, else the one with the smallest objective (among the plants that
  // compute one; a constraints-only plant contributes its constraints and margins).
  const auto full = [&](std::size_t i) { return !plants[i]->constraints_only(); };
  std::size_t lowest = per.size();
  for (std::size_t i = 0; i < per.size(); ++i)
    if (full(i) && (lowest == per.size() || per[i].objective < per[lowest].objective)) lowest = i;
  std::size_t wi = lowest == per.size() ? 0 : lowest;
  for (std::size_t i = 0; i < per.size(); ++i)
    if (per[i].violation > per[wi].violation) wi = i;
  Evaluation w = per[wi];
  if (!full(wi) && lowest != per.size()) w.objective = per[lowest].objective;
  if (!w.binding.empty()) w.binding = w.plant + ": " + w.binding;
  // Margins and depths: the smallest over the plants; peaks and shares of a limit: the largest.
  constexpr double Evaluation::*kMargins[] = {&Evaluation::gain_margin_db, &Evaluation::phase_margin_deg,
                                              &Evaluation::delay_margin_ms, &Evaluation::k_max_ns_per_m,
                                              &Evaluation::worst_mode_improvement_pct};
  constexpr double Evaluation::*kDepths[] = {&Evaluation::min_depth_mm, &Evaluation::depth_at_speed_mm,
                                             &Evaluation::floor_ratio, &Evaluation::accurate_min_mm,
                                             &Evaluation::open_minima_ratio};
  constexpr double Evaluation::*kLargest[] = {&Evaluation::worst_mode_phase_deg, &Evaluation::peak_m_per_n,
                                              &Evaluation::peak_coil_force_n,    &Evaluation::peak_command_v,
                                              &Evaluation::peak_slew_v_per_s,    &Evaluation::actuator_use,
                                              &Evaluation::quiet_command_rms_v};
  if (!full(wi) && lowest != per.size())
    for (const auto field : kDepths) w.*field = per[lowest].*field;
  for (std::size_t i = 0; i < per.size(); ++i) {
    const Evaluation& e = per[i];
    w.stable = w.stable && e.stable;
    for (const auto field : kMargins) w.*field = std::min(w.*field, e.*field);
    if (full(i))
      for (const auto field : kDepths) w.*field = std::min(w.*field, e.*field);
    for (const auto field : kLargest) w.*field = std::max(w.*field, e.*field);
  }
  w.per_plant = std::move(per);
  return w;
}

namespace {

// x = [log10 K, log10 fz, zeta_z, log10 fp, zeta_p, log10 fa, log10 fb]
constexpr unsigned kDims = 7;
const double kLower[kDims] = {
    std::log10(kGainMinNsPerM),   std::log10(kPairMinHz),      kZetaMin, std::log10(kPairMinHz), kZetaMin,
    std::log10(kFirstOrderMinHz), std::log10(kFirstOrderMinHz)};
const double kUpper[kDims] = {
    std::log10(kGainMaxNsPerM),   std::log10(kPairMaxHz),      kZetaMax, std::log10(kPairMaxHz), kZetaMax,
    std::log10(kFirstOrderMaxHz), std::log10(kFirstOrderMaxHz)};

Candidate candidate_of(const double* x, int polarity) {
  return {std::pow(10.0, x[0]), std::pow(10.0, x[1]), x[2],    std::pow(10.0, x[3]), x[4],
          std::pow(10.0, x[5]), std::pow(10.0, x[6]), polarity};
}

struct Search {
  const std::vector<const Evaluator*>* plants;
  int polarity;
  TuneResult* result;
  const std::function<void(const std::string&)>* progress;
  const char* phase;
  int budget;
  int count{0};
};

double penalised(unsigned /*n*/, const double* x, double* /*grad*/, void* data) {
  auto& s = *static_cast<Search*>(data);
  const Evaluation e = evaluate_worst(*s.plants, candidate_of(x, s.polarity), true);
  s.result->history.push_back(e);
  if (s.result->history.size() == 1 || better(e, s.result->best)) s.result->best = e;
  ++s.count;
  if (*s.progress && (s.count % 20 == 0 || s.count == s.budget)) {
    const Evaluation& b = s.result->best;
    char line[200];
    std::snprintf(line, sizeof line, "tune: polarity %+d, %s %d/%d; best so far %s %.4g, %s", s.polarity, s.phase,
                  s.count, s.budget, b.peak_m_per_n > 0.0 ? "-log10 peak" : "min depth mm", b.objective,
                  b.feasible() ? "feasible" : ("violates " + b.binding).c_str());
    (*s.progress)(line);
  }
  // Larger is better; a violated constraint costs more than any objective can gain.
  const double objective = std::isfinite(e.objective) ? e.objective : -1e3;
  return objective - 1e3 * e.violation;
}

void run(nlopt_algorithm algorithm, Search& s, std::vector<double>& x) {
  nlopt_opt opt = nlopt_create(algorithm, kDims);
  nlopt_set_lower_bounds(opt, kLower);
  nlopt_set_upper_bounds(opt, kUpper);
  nlopt_set_max_objective(opt, penalised, &s);
  nlopt_set_maxeval(opt, s.budget);
  double f = 0.0;
  (void)nlopt_optimize(opt, x.data(), &f);  // the best point is kept in s.result whatever the return code
  nlopt_destroy(opt);
}

std::vector<double> x_of(const Candidate& c) {
  return {std::log10(c.gain_ns_per_m), std::log10(c.fz_hz), c.zeta_z, std::log10(c.fp_hz), c.zeta_p,
          std::log10(c.fa_hz),         std::log10(c.fb_hz)};
}

}  // namespace

TuneResult tune(const config::Config& base, const std::optional<config::MillingConfig>& job, const TuneSettings& s,
                const std::function<void(const std::string&)>& progress) {
  const Evaluator evaluate(base, job, s);
  return tune(std::vector<const Evaluator*>{&evaluate}, s, progress);
}

namespace {

// One polarity's search (seeded global, then the polish), its evaluations and best added to `result`.
void search_polarity(const std::vector<const Evaluator*>& plants, const TuneSettings& s, int polarity,
                     const std::function<void(const std::string&)>& progress, const std::string& tag,
                     TuneResult& result, const std::optional<Candidate>& start = std::nullopt) {
  const config::Config& base = plants.front()->base();
  TuneResult per;
  const std::string global_phase = "global search" + tag, local_phase = "local polish" + tag;
  Search global{&plants, polarity, &per, &progress, global_phase.c_str(), s.global_evaluations};
  // From C1's shape (the actuator's resonance cancelled, poles at 0.5 Hz) at the configured gain.
  const Candidate c1{std::clamp(base.controller.gain_ns_per_m, kGainMinNsPerM, kGainMaxNsPerM),
                     base.actuator.natural_freq_hz,
                     base.actuator.damping_ratio,
                     0.5,
                     1.0,
                     10.0,
                     10.0,
                     polarity};
  std::vector<double> x = x_of(start ? *start : c1);
  for (unsigned i = 0; i < kDims; ++i) x[i] = std::clamp(x[i], kLower[i], kUpper[i]);
  run(NLOPT_GN_CRS2_LM, global, x);
  if (s.local_evaluations > 0) {  // NLopt reads a budget of 0 as no limit
    Search local{&plants, polarity, &per, &progress, local_phase.c_str(), s.local_evaluations};
    x = x_of(per.best.candidate);
    run(NLOPT_LN_BOBYQA, local, x);
  }
  const bool first = result.history.empty();
  result.history.insert(result.history.end(), per.history.begin(), per.history.end());
  if (first || better(per.best, result.best)) result.best = per.best;
}

}  // namespace

TuneResult tune_from(const std::vector<const Evaluator*>& plants, const Candidate& start, const TuneSettings& s,
                     const std::function<void(const std::string&)>& progress) {
  if (plants.empty()) throw std::invalid_argument("robodamp tune: no plant to tune for");
  TuneResult result;
  result.best = evaluate_worst(plants, start);
  result.history.push_back(result.best);
  nlopt_srand(static_cast<unsigned long>(s.seed));
  search_polarity(plants, s, start.polarity, progress, "", result, start);
  return result;
}

TuneResult tune(const std::vector<const Evaluator*>& plants, const TuneSettings& s,
                const std::function<void(const std::string&)>& progress) {
  if (plants.empty()) throw std::invalid_argument("robodamp tune: no plant to tune for");
  TuneResult result;
  for (int restart = 0; restart < std::max(1, s.restarts); ++restart) {
    const int seed = s.seed + restart;
    nlopt_srand(static_cast<unsigned long>(seed));  // CRS2's population: seeded, so a tune repeats exactly
    const std::string tag = s.restarts > 1 ? " (seed " + std::to_string(seed) + ")" : "";
    for (const int polarity : {1, -1}) search_polarity(plants, s, polarity, progress, tag, result);
  }
  return result;
}

}  // namespace robodamp::tune
