#include "commission/cell_check.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "analysis/bench_run.hpp"
#include "analysis/loop_model.hpp"
#include "analysis/modal_test.hpp"
#include "commission/modal_test_hook.hpp"
#include "runtime/cell.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp::commission {

namespace {

constexpr double kRampMarginS = 2.0;  // after the measurement's settle: the gain ramp done

struct ImpactRun {
  std::vector<std::vector<analysis::FrfEstimate>> receptance;  // [excitation location][response location]
  std::string trip{"none"};
  double active_share{0.0};
  unsigned long long saturated_ticks{0};
};

// Hammer impacts at every location, one location after the other, once the loop is active at full gain:
// the configuration `run` drives the cell's plant (`cell`).
ImpactRun impacts_on_cell(const config::Config& run, const config::Config& cell) {
  analysis::CommissioningPlan plan;
  const auto& c = cell.commissioning;
  plan.chirp_start_s = plan.chirp_end_s = c.settle_s;
  const double per_location = c.impacts_per_location * (c.record_s + 1.0);
  double t = c.settle_s + run.controller.gain_ramp_s + kRampMarginS;
  const double first = t;
  for (std::size_t l = 0; l < cell.robot.locations.size(); ++l, t += per_location) plan.impacts_start_s.push_back(t);
  const double last = t;  // the impacts' records end before this
  plan.duration_s = t + 1.0;
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  o.plant_config = cell;
  o.keep_frames = true;
  runtime::Cell rc(run, o);
  if (runtime::Status s = rc.configure(); !s.ok()) throw std::runtime_error("the cell: " + s.message);
  if (rc.hardware()) throw std::runtime_error("the check on the cell needs the simulated plant");
  analysis::ModalTest test(cell, rc.plant(), plan);
  ModalTestHook hook(test);
  rc.sim_backend().set_step_hook(&hook);
  if (runtime::Status s = rc.activate(plan.duration_s); !s.ok()) throw std::runtime_error("the cell: " + s.message);
  rc.wait();
  (void)rc.deactivate();
  ImpactRun out;
  out.trip = rc.summary().trip;
  out.saturated_ticks = rc.summary().supervisor.saturated_ticks;
  std::size_t in = 0, active = 0;
  for (const auto& f : rc.frames()) {
    if (f.time_s < first || f.time_s >= last) continue;
    ++in;
    if (f.state == static_cast<std::uint8_t>(rt::State::kActive)) ++active;
  }
  out.active_share = in == 0 ? 0.0 : static_cast<double>(active) / static_cast<double>(in);
  out.receptance = test.receptance();
  return out;
}

std::size_t index_of(const sim::PlantModel& m, int id) {
  for (std::size_t i = 0; i < m.locations.size(); ++i)
    if (m.locations[i].id == id) return i;
  throw std::invalid_argument("location " + std::to_string(id) + " is not in the cell's configuration");
}

}  // namespace

config::Config with_controller_of(const config::Config& cell, const config::Config& tuned) {
  config::Config c = cell;
  c.controller = tuned.controller;
  if (!c.controller.match_freq_hz) c.controller.match_freq_hz = tune::unity_gain_hz(tuned);
  return c;
}

bool CellCheck::improvement_ok() const {
  if (frfs.empty() || open_trip != "none" || closed_trip != "none" || closed_active_share < 1.0) return false;
  for (const auto& f : frfs)
    if (!(std::abs(f.measured_improvement_pct - f.predicted_improvement_pct) <= improvement_tolerance_points))
      return false;
  return true;
}

bool CellCheck::depth_ok(const tune::Verification& p) const {
  if (!cut_trials.empty()) {
    for (const auto& t : cut_trials)
      if (!t.held()) return false;
    return true;
  }
  return time_domain_at_min_mm >= (1.0 - depth_tolerance) * p.min_depth_mm &&
         time_domain_at_speed_mm >= (1.0 - depth_tolerance) * p.depth_at_speed_mm;
}

std::string CellCheck::failure(const tune::Verification& p) const {
  char b[400];
  if (closed_trip != "none") return "the cell tripped with the tuned controller (" + closed_trip + ")";
  if (open_trip != "none") return "the cell tripped with control off (" + open_trip + ")";
  if (closed_active_share < 1.0) {
    std::snprintf(b, sizeof b, "the loop was active over only %.1f %% of the impact tests",
                  100.0 * closed_active_share);
    return b;
  }
  for (const auto& f : frfs)
    if (!(std::abs(f.measured_improvement_pct - f.predicted_improvement_pct) <= improvement_tolerance_points)) {
      std::snprintf(b, sizeof b, "%s: measured improvement %.1f %% against %.1f %% predicted (allowed +-%.0f points)",
                    f.name.c_str(), f.measured_improvement_pct, f.predicted_improvement_pct,
                    improvement_tolerance_points);
      return b;
    }
  if (!depth_ok(p) && !cut_trials.empty()) return "the damped cut on the cell: " + cut_summary(p);
  if (!depth_ok(p)) {
    std::snprintf(
        b, sizeof b,
        "the damped cut on the cell: %.3f mm at %.1f rpm (promised %.3f mm) and %.3f mm at %.1f rpm (promised "
        "%.3f mm); allowed %.0f %% below",
        time_domain_at_min_mm, p.min_rpm, p.min_depth_mm, time_domain_at_speed_mm, p.speed_rpm, p.depth_at_speed_mm,
        100.0 * depth_tolerance);
    return b;
  }
  return {};
}

std::string CellCheck::cut_summary(const tune::Verification& p) const {
  char b[300];
  if (cut_trials.empty()) {
    std::snprintf(
        b, sizeof b,
        "the damped cut in time in process (the real Controller on the cell's plant): critical %.3f mm at %.1f "
        "rpm (promised %.3f mm), %.3f mm at %.1f rpm (promised %.3f mm)",
        time_domain_at_min_mm, p.min_rpm, p.min_depth_mm, time_domain_at_speed_mm, p.speed_rpm, p.depth_at_speed_mm);
    return b;
  }
  std::string s =
      "the regenerative cut in the HIL emulator (its drive vibration off, as the in-process cut) with the tuned "
      "controller across processes, at the promise less " +
      std::to_string(static_cast<int>(std::lround(100.0 * depth_tolerance))) + " %:";
  for (std::size_t i = 0; i < cut_trials.size(); ++i) {
    const CutTrial& t = cut_trials[i];
    std::snprintf(b, sizeof b, "%s %.3f mm at %.1f rpm %s", i ? ";" : "", t.depth_mm, t.rpm,
                  t.held() ? "stable" : t.classification.c_str());
    s += b;
    if (!t.held() && t.chatter_hz > 0.0) std::snprintf(b, sizeof b, " at %.2f Hz", t.chatter_hz), s += b;
    if (t.trip != "none")
      s += " (the controller tripped: " + t.trip + ")";
    else if (t.complete && t.active_share < 1.0)
      std::snprintf(b, sizeof b, " (the loop active over %.1f %% of it)", 100.0 * t.active_share), s += b;
  }
  return s;
}

std::vector<FrfCheck> frf_checks(const config::Config& tuned, const ReceptanceOf& open, const ReceptanceOf& closed) {
  std::vector<FrfCheck> out;
  const analysis::LoopModel model(tuned);
  const analysis::AnalysisResult an = analysis::analyse(model);
  const double lo = tuned.analysis.band_min_hz, hi = tuned.analysis.band_max_hz;
  const double k = tuned.controller.gain_ns_per_m;
  const int pol = tuned.controller.polarity;
  for (std::size_t i = 0; i < an.frfs_discrete.size(); ++i) {
    const auto& pf = an.frfs_discrete[i];
    const auto& fc = tuned.robot.frfs[i];
    FrfCheck f;
    f.name = fc.name;
    f.response_id = fc.response_location;
    f.excitation_id = fc.excitation_location;
    const analysis::FrfEstimate& mo = open(f.excitation_id, f.response_id);
    const analysis::FrfEstimate& mc = closed(f.excitation_id, f.response_id);
    const analysis::MeasuredPeak po = analysis::measured_peak(mo, lo, hi), pc = analysis::measured_peak(mc, lo, hi);
    f.open_peak_m_per_n = po.magnitude_m_per_n;
    f.closed_peak_m_per_n = pc.magnitude_m_per_n;
    f.open_peak_hz = po.freq_hz;
    f.closed_peak_hz = pc.freq_hz;
    f.coherence_min = std::min(po.coherence_min, pc.coherence_min);
    f.measured_improvement_pct = (po.magnitude_m_per_n / pc.magnitude_m_per_n - 1.0) * 100.0;
    f.predicted_improvement_pct = pf.improvement_pct;
    for (std::size_t b = 0; b < mo.f_hz.size() && b < mc.f_hz.size(); ++b) {
      const double fh = mo.f_hz[b];
      if (fh < lo || fh > hi) continue;
      const analysis::PlantResponse p = model.plant_response(fh);
      f.f_hz.push_back(fh);
      f.measured_open.push_back(std::abs(mo.h1[b]));
      f.measured_closed.push_back(std::abs(mc.h1[b]));
      f.predicted_open.push_back(std::abs(model.open_discrete(p, pf.response, pf.excitation)));
      f.predicted_closed.push_back(
          std::abs(model.closed_discrete(p, model.chain_filters_digital(fh), pf.response, pf.excitation, k, pol)));
    }
    out.push_back(std::move(f));
  }
  return out;
}

CellCheck check_on_cell(const config::Config& cell, const config::Config& tuned, const config::MillingConfig& job,
                        const tune::Verification& promise) {
  const auto t0 = std::chrono::steady_clock::now();
  CellCheck out;
  config::Config off = tuned;
  off.controller.gain_ns_per_m = 0.0;
  const ImpactRun open = impacts_on_cell(off, cell), closed = impacts_on_cell(tuned, cell);
  out.open_trip = open.trip;
  out.closed_trip = closed.trip;
  out.closed_active_share = closed.active_share;
  out.closed_saturated_ticks = closed.saturated_ticks;

  const sim::PlantModel cell_plant = sim::build_plant_model(cell);
  out.frfs = frf_checks(
      tuned,
      [&](int e, int r) -> const analysis::FrfEstimate& {
        return open.receptance.at(index_of(cell_plant, e)).at(index_of(cell_plant, r));
      },
      [&](int e, int r) -> const analysis::FrfEstimate& {
        return closed.receptance.at(index_of(cell_plant, e)).at(index_of(cell_plant, r));
      });
  const config::Config on_cell = with_controller_of(cell, tuned);
  out.time_domain_at_min_mm = tune::time_domain_critical_mm(on_cell, job, promise.min_rpm, promise.min_depth_mm);
  out.time_domain_at_speed_mm =
      tune::time_domain_critical_mm(on_cell, job, promise.speed_rpm, promise.depth_at_speed_mm);
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace robodamp::commission
