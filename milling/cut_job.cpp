#include "milling/cut_job.hpp"

#include <cmath>
#include <string>

#include "config/number_range.hpp"
#include "milling/damped_dynamics.hpp"
#include "units/units.hpp"

namespace robodamp::milling {

CutJob make_cut_job(const config::MillingConfig& cfg, const Structure& structure, const CutOverrides& o) {
  std::vector<config::Problem> problems;
  auto check = [&](const std::string& key, double v, const config::Range& range) {
    if (auto p = config::range_problem(key, v, range)) problems.push_back({cfg.source, {}, key, *p});
  };
  CutJob j;
  j.cutter = cutter_from(cfg.tool);
  j.material = cfg.material;
  j.terms = cutter_modal_terms(structure, cfg.cut.feed_axis);
  if (j.terms.empty())
    problems.push_back({cfg.source,
                        {},
                        "structures." + structure.name(),
                        "structures." + structure.name() + " has no modes to simulate"});
  for (const auto& t : j.terms) j.highest_mode_hz = std::max(j.highest_mode_hz, t.wn_rad_per_s / (kTwoPi));
  const config::TimeDomainConfig& td = cfg.time_domain;
  CutSettings& s = j.settings;
  s.rpm = o.rpm.value_or(cfg.cut.spindle_rpm);
  s.cut = {cfg.cut.mode, o.radial_mm.value_or(cfg.cut.radial_mm), o.axial_mm.value_or(cfg.cut.axial_mm),
           cfg.cut.feed_per_tooth_mm};
  s.revolutions = o.revolutions.value_or(td.revolutions);
  s.settle_revolutions = td.settle_revolutions;
  s.axial_slices = td.axial_slices;
  s.runout_um = td.runout_um;
  s.pitch_deg = td.pitch_deg;
  check(o.rpm ? "--rpm" : "cut.spindle_rpm", s.rpm, {"rpm", 0.0, 200000.0, true, false});
  check(o.axial_mm ? "--axial-mm" : "cut.axial_mm", s.cut.axial_mm,
        {"mm", 0.0, cfg.tool.flute_length_mm, true, false, "the tool's tool.flute_length_mm"});
  check(o.radial_mm ? "--radial-mm" : "cut.radial_mm", s.cut.radial_mm,
        {"mm", 0.0, cfg.tool.diameter_mm, true, false, "the tool's diameter"});
  check(o.revolutions ? "--revs" : "time_domain.revolutions", s.revolutions,
        {"(revolutions)", static_cast<double>(td.settle_revolutions + 8), 100000.0, false, false,
         "time_domain.settle_revolutions + 8 for the statistics"});
  j.damped = o.damped;
  j.requested_rpm = s.rpm;
  if (o.damped && structure.controller_parts().empty())
    problems.push_back({cfg.source,
                        {},
                        "--damped",
                        "--damped needs a structure part with a controller (a damping configuration); structures." +
                            structure.name() + " has none"});
  if (problems.empty() && o.damped) {
    // The controller steps at its loop rate, so the cut does: the tooth period is made a whole number of
    // loop periods (the speed moves by at most half a loop period per tooth period).
    const double loop_s = 1.0 / structure.controller_parts().front().model->loop_rate_hz();
    const double tooth_s = 60.0 / (s.rpm * cfg.tool.teeth);
    s.steps_per_tooth = std::max(1, static_cast<int>(std::lround(tooth_s / loop_s)));
    s.rpm = 60.0 / (cfg.tool.teeth * s.steps_per_tooth * loop_s);
    const Structure* st = &structure;
    const config::Axis feed = cfg.cut.feed_axis;
    j.dynamics = [st, feed] { return std::make_unique<DampedDynamics>(*st, feed); };
  } else if (problems.empty() && s.rpm > 0.0) {
    s.steps_per_tooth = steps_per_tooth(td, j.highest_mode_hz, s.rpm, cfg.tool.teeth);
    const double tooth_s = 60.0 / (s.rpm * cfg.tool.teeth);
    const double needed = std::ceil(td.min_steps_per_mode_period * j.highest_mode_hz * tooth_s);
    if (td.steps_per_tooth > 0 && td.steps_per_tooth < needed)
      problems.push_back(
          {cfg.source,
           {},
           "time_domain.steps_per_tooth",
           "time_domain.steps_per_tooth = " + std::to_string(td.steps_per_tooth) +
               " steps is too coarse for the modes: allowed >= " + config::format_number(needed) +
               " steps (time_domain.min_steps_per_mode_period = " + std::to_string(td.min_steps_per_mode_period) +
               " per period of the " + config::format_number(j.highest_mode_hz) + " Hz mode at " +
               config::format_number(s.rpm) + " rpm)"});
  }
  if (!problems.empty()) throw config::ConfigError(problems);
  if (!j.damped) {
    const double h = 60.0 / (s.rpm * cfg.tool.teeth) / s.steps_per_tooth;
    const auto terms = j.terms;
    j.dynamics = [terms, h] { return std::make_unique<ToolDynamics>(terms, h); };
  }
  return j;
}

CutOutcome run_job(const CutJob& job) {
  const std::unique_ptr<CutDynamics> dyn = job.dynamics();
  CutOutcome o = run_cut(*dyn, job.cutter, job.material, job.settings);
  if (const auto* d = dynamic_cast<const DampedDynamics*>(dyn.get())) {
    o.record.peak_actuator_force_n = d->stats().peak_actuator_force_n;
    o.record.actuator_saturated_s = d->stats().saturated_s;
  }
  return o;
}

}  // namespace robodamp::milling
