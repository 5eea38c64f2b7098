#include "hil/regenerative_cut.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "analysis/loop_model.hpp"
#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"
#include "milling/damped_dynamics.hpp"
#include "milling/structure.hpp"
#include "config/number_range.hpp"
#include "units/units.hpp"

namespace robodamp::hil {

namespace {

constexpr int kMinRevolutions = 300;  // as the commissioning's time-domain check: a slow decay is not chatter
// The drive vibration's forced response taken out: its frequency and harmonics (the amplifier's and the
// converters' steps make them) up to kForcedHarmonics, each +- up to kForcedSidebands x the tooth frequency
// (the cut's periodic force modulates them).
constexpr int kForcedHarmonics = 3;
constexpr int kForcedSidebands = 3;

// Least-squares sinusoids at the given frequencies fitted to x[start..] and subtracted there (the normal
// equations accumulated sample by sample: a record of 10^5-10^6 samples needs no tall matrix).
void remove_tones(std::vector<double>& x, std::size_t start, double fs, const std::vector<double>& freqs_hz) {
  const auto m = static_cast<Eigen::Index>(2 * freqs_hz.size());
  if (freqs_hz.empty() || x.size() <= start + static_cast<std::size_t>(4 * m)) return;
  std::vector<std::complex<double>> rot, ph(freqs_hz.size(), 1.0);
  for (const double f : freqs_hz) rot.push_back(std::polar(1.0, kTwoPi * f / fs));
  Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd atb = Eigen::VectorXd::Zero(m), row(m);
  auto next_row = [&](std::size_t i) {
    for (std::size_t k = 0; k < freqs_hz.size(); ++k) {
      row(static_cast<Eigen::Index>(2 * k)) = ph[k].real(), row(static_cast<Eigen::Index>(2 * k + 1)) = ph[k].imag();
      ph[k] *= rot[k];
      if (i % 1024 == 0) ph[k] /= std::abs(ph[k]);  // the rotation's rounding kept off the unit circle's drift
    }
  };
  for (std::size_t i = start; i < x.size(); ++i) {
    next_row(i);
    ata.selfadjointView<Eigen::Lower>().rankUpdate(row);
    atb += row * x[i];
  }
  const Eigen::VectorXd c = ata.selfadjointView<Eigen::Lower>().ldlt().solve(atb);
  std::fill(ph.begin(), ph.end(), std::complex<double>(1.0));
  for (std::size_t i = start; i < x.size(); ++i) {
    next_row(i);
    x[i] -= row.dot(c);
  }
}

// The drive vibration's forced lines at a tooth frequency: fd and its harmonics +- the tooth harmonics,
// without the cut's own harmonics and above Nyquist.
std::vector<double> forced_tones(double fd_hz, double ft_hz, double nyquist_hz) {
  std::vector<double> out;
  if (!(fd_hz > 0.0)) return out;
  for (int h = 1; h <= kForcedHarmonics; ++h)
    for (int k = -kForcedSidebands; k <= kForcedSidebands; ++k) {
      const double f = std::abs(h * fd_hz + k * ft_hz);
      const double to_harmonic = std::abs(f / ft_hz - std::round(f / ft_hz)) * ft_hz;  // the cut's own stay
      const bool seen = std::any_of(out.begin(), out.end(), [f](double g) { return std::abs(g - f) < 1e-9; });
      if (f > 0.0 && f < nyquist_hz && to_harmonic > 1e-6 && !seen) out.push_back(f);
    }
  return out;
}

milling::ChatterIndicatorSettings indicator_settings(const config::Config& cfg, const std::string& job_path) {
  milling::ChatterIndicatorSettings s;  // as robodamp run's (runtime/machining_monitor.cpp)
  s.band_min_hz = cfg.analysis.band_min_hz;
  s.lines_per_revolution = milling::forced_lines_per_revolution(config::load_milling_config(job_path));
  return s;
}

constexpr double kIndicatorPeriodS = 0.1;  // plant time between the live indicator's evaluations

}  // namespace

RegenerativeCut::RegenerativeCut(const config::Config& cfg, sim::Plant& plant, const RegenerativeCutOptions& o)
    : plant_(plant), speed_({}), depth_({}), indicator_(1.0 / plant.period_s(), indicator_settings(cfg, o.job_path)) {
  const config::MillingConfig job = config::load_milling_config(o.job_path);
  // The job's structure with its controller part on this cell: the part's location and direction are where
  // the cut acts on the plant; its loop rate is the cut's step.
  const milling::Structure structure(
      job.selected_structure(), false,
      {std::make_shared<const analysis::LoopModel>(cfg), cfg.controller.gain_ns_per_m, cfg.controller.polarity});
  if (structure.controller_parts().empty())
    throw config::ConfigError({{job.source,
                                {},
                                "structures." + job.structure,
                                "the emulator's cut acts on the robot at the structure's controller part; structures." +
                                    job.structure + " has none"}});
  milling::CutOverrides co;
  co.rpm = o.rpm, co.axial_mm = o.axial_mm, co.damped = true;
  co.revolutions = o.revolutions.value_or(std::max(job.time_domain.revolutions, kMinRevolutions));
  const milling::CutJob cj = milling::make_cut_job(job, structure, co);
  // The program's speeds within the spindle's range, its depths within the tool's cutting length.
  std::vector<config::Problem> problems;
  const config::Range speeds{"rpm", 0.0, cfg.spindle.rpm_max, true, false, "spindle.rpm_max of " + cfg.source};
  const config::Range depths{"mm", 0.0, job.tool.flute_length_mm, true, false, "tool.flute_length_mm of " + job.source};
  if (auto p = config::range_problem(o.rpm ? "--cut-rpm" : "cut.spindle_rpm", cj.requested_rpm, speeds))
    problems.push_back({job.source, {}, o.rpm ? "--cut-rpm" : "cut.spindle_rpm", *p});
  for (const auto& c : o.spindle)
    if (auto p = config::range_problem("--spindle", c.rpm, speeds))
      problems.push_back({job.source, {}, "--spindle", *p});
  for (const auto& c : o.depth)
    if (auto p = config::range_problem("--depth", c.rpm, depths)) problems.push_back({job.source, {}, "--depth", *p});
  if (!problems.empty()) throw config::ConfigError(problems);
  cutter_ = cj.cutter, material_ = cj.material, settings_ = cj.settings;
  requested_rpm_ = cj.requested_rpm;
  feed_ = job.cut.feed_axis;
  const auto& part = structure.controller_parts().front();
  location_ = part.location, direction_ = part.direction;
  // The program: the speed and depth from the values above, then its steps and ramps.
  std::vector<SpindleChange> speed{{0.0, 0.0, cj.requested_rpm}}, depth{{0.0, 0.0, settings_.cut.axial_mm}};
  speed.insert(speed.end(), o.spindle.begin(), o.spindle.end());
  depth.insert(depth.end(), o.depth.begin(), o.depth.end());
  for (const auto& c : o.spindle) program_end_s_ = std::max(program_end_s_, c.t1_s);
  for (const auto& c : o.depth) program_end_s_ = std::max(program_end_s_, c.t1_s);
  program_end_s_ = std::max(program_end_s_, o.until_s);
  awaiting_advice_ = o.until_advice;
  speed_ = SpindleProfile(std::move(speed)), depth_ = SpindleProfile(std::move(depth));
  program_period_s_ = std::max(o.program_period_s, plant.period_s());
  process_.emplace(cutter_, material_, settings_);
  const milling::Structure tables(structure.modal_terms_by_pair(), structure.name());
  if (const auto terms = milling::cutter_modal_terms(tables, feed_); !terms.empty())
    tables_ = std::make_unique<milling::ToolDynamics>(terms, plant.period_s());
  auto force = std::make_unique<sim::HeldForce>(location_);
  force_ = force.get();
  plant_.add_excitation(std::move(force));
  auto_delay_s_ = cfg.hil.settle_s + cfg.controller.gain_ramp_s;
  // The robot's own vibration with the drives on is a forced motion at its frequency and, through the
  // cut's tooth-periodic force, at that frequency +- the tooth harmonics: not the cut's regeneration.
  if (cfg.disturbances.drives_on) drive_hz_ = cfg.disturbances.drive_vibration_hz;
  rep_.cut = true;
  rep_.job = o.job_path;
  rep_.radial_mm = settings_.cut.radial_mm;
  rep_.teeth = cutter_.teeth;
  rep_.revolutions = settings_.revolutions, rep_.settle_revolutions = settings_.settle_revolutions;
  rep_.start_s = o.start_s;
}

milling::CutSettings RegenerativeCut::settings_for(double rpm, double axial_mm) const {
  milling::CutSettings s = settings_;
  // As make_cut_job with the damper: the tooth period a whole number of loop periods.
  const double tooth_s = 60.0 / (rpm * cutter_.teeth);
  s.steps_per_tooth = std::max(1, static_cast<int>(std::lround(tooth_s / plant_.period_s())));
  s.rpm = 60.0 / (cutter_.teeth * s.steps_per_tooth * plant_.period_s());
  s.cut.axial_mm = axial_mm;
  return s;
}

void RegenerativeCut::amplifier_ready(double t_s) {
  if (rep_.start_s < 0.0) rep_.start_s = t_s + auto_delay_s_;
}

void RegenerativeCut::advice_read(double t_s) {
  if (!awaiting_advice_) return;
  awaiting_advice_ = false;
  program_end_s_ = std::max(program_end_s_, t_s);
}

void RegenerativeCut::follow_advice(double rpm, double t_s) {
  if (!(rpm > 0.0) || ended_) return;
  advised_rpm_ = rpm;
  program_end_s_ = std::max(program_end_s_, t_s);
  next_program_s_ = t_s;  // at the next step
}

Eigen::Vector2d RegenerativeCut::displacement() const {
  Eigen::Vector2d machine = Eigen::Vector2d::Zero();
  machine(static_cast<Eigen::Index>(direction_)) = plant_.displacement_m(location_);
  return milling::to_cutter(machine, feed_) + (tables_ ? tables_->displacement() : Eigen::Vector2d::Zero());
}

void RegenerativeCut::change_to(double requested_rpm, double axial_mm, const char* cause, double t_s) {
  const milling::CutSettings next = settings_for(requested_rpm, axial_mm);
  if (next.steps_per_tooth == settings_.steps_per_tooth && next.cut.axial_mm == settings_.cut.axial_mm) return;
  milling::CutProcess p(cutter_, material_, next);
  const std::size_t k = started_ ? p.continue_from(*process_, process_k_) : 0;
  process_.emplace(std::move(p));
  process_k_ = k;
  settings_ = next;
  requested_rpm_ = requested_rpm;
  if (!started_) return;
  segments_.back().head.end_s = t_s;
  start_segment(cause, t_s);
}

void RegenerativeCut::start_segment(const char* cause, double t_s) {
  Segment s;
  s.head.cause = cause, s.head.start_s = t_s;
  s.head.requested_rpm = requested_rpm_, s.head.rpm = settings_.rpm, s.head.axial_mm = settings_.cut.axial_mm;
  s.head.steps_per_tooth = settings_.steps_per_tooth;
  const std::size_t steps = process_->steps_per_revolution() * static_cast<std::size_t>(settings_.revolutions);
  s.x_m.reserve(steps), s.y_m.reserve(steps);
  segments_.push_back(std::move(s));
  indicator_.reset();  // another speed: the window restarts, as robodamp run's does
}

void RegenerativeCut::before_step(double t_s) {
  force_->value_n = 0.0;
  t_s_ = t_s;
  if (ended_) return;
  if (t_s >= next_program_s_) {  // the program (or the advice) at its register's pace
    next_program_s_ = t_s + program_period_s_;
    const double rpm = advised_rpm_ > 0.0 ? advised_rpm_ : speed_.rpm(t_s);
    change_to(rpm, depth_.rpm(t_s), advised_rpm_ > 0.0 ? "advice" : "program", t_s);
  }
  if (!started_) {
    if (rep_.start_s < 0.0 || t_s < rep_.start_s) return;
    started_ = true;
    previous_ = last_ = displacement();
    start_segment("start", t_s);
  }
  Segment& seg = segments_.back();
  // As the in-process cut: the displacement at the step's middle from its start and a linear look-ahead.
  const Eigen::Vector2d q = displacement(), q_end = 2.0 * last_ - previous_;
  const std::size_t settle = process_->steps_per_revolution() * static_cast<std::size_t>(settings_.settle_revolutions);
  const bool stats = seg.steps >= settle;
  const std::uint64_t engaged = process_->engaged_samples(), out = process_->out_of_cut_samples();
  f_ = process_->force(process_k_, 0.5 * (q + q_end), stats);
  seg.engaged += process_->engaged_samples() - engaged, seg.out_of_cut += process_->out_of_cut_samples() - out;
  if (stats) rep_.peak_force_n = std::max(rep_.peak_force_n, f_.norm());
  if (seg.x_m.size() < seg.x_m.capacity()) seg.x_m.push_back(q(0)), seg.y_m.push_back(q(1));
  q_start_ = q;
  force_->value_n = milling::to_machine(f_, feed_)(static_cast<Eigen::Index>(direction_));
}

void RegenerativeCut::after_step() noexcept {
  if (!started_ || ended_) return;
  if (tables_) tables_->step(f_);
  previous_ = last_;
  last_ = displacement();
  process_->end_step(q_start_, last_);
  ++process_k_;
  Segment& seg = segments_.back();
  const std::size_t whole = process_->steps_per_revolution() * static_cast<std::size_t>(settings_.revolutions);
  // The last segment's revolutions done after the program's last change: the tool leaves the cut.
  if (++seg.steps >= whole && t_s_ >= program_end_s_ && !awaiting_advice_) {
    ended_ = true, rep_.complete = true;
    rep_.end_s = seg.head.end_s = t_s_ + plant_.period_s();
  }
}

void RegenerativeCut::sensed(double accel_mps2, double t_s) {
  if (!active()) return;
  indicator_.push(accel_mps2);
  if (t_s < next_indicator_s_) return;
  next_indicator_s_ = t_s + kIndicatorPeriodS;
  const milling::ChatterIndicator c = indicator_.evaluate(settings_.rpm);
  if (!c.valid) return;
  CutSegment& h = segments_.back().head;
  if (c.chatter && h.indicator_chatter_s < 0.0) h.indicator_chatter_s = t_s;
  // Quiet: the first clear evaluation in a segment after one that chattered.
  const bool before_chattered = segments_.size() > 1 && segments_[segments_.size() - 2].head.indicator_chatter_s >= 0.0;
  if (!c.chatter && h.indicator_quiet_s < 0.0 && h.indicator_chatter_s < 0.0 && before_chattered)
    h.indicator_quiet_s = t_s;
}

CutSegment RegenerativeCut::judged(const Segment& s) const {
  CutSegment h = s.head;
  const int m = s.head.steps_per_tooth;
  const std::size_t per_rev = static_cast<std::size_t>(cutter_.teeth * m);
  h.revolutions = static_cast<double>(s.steps) / static_cast<double>(per_rev);
  if (h.end_s <= h.start_s) h.end_s = h.start_s + static_cast<double>(s.steps) * plant_.period_s();
  const std::size_t settle = per_rev * static_cast<std::size_t>(settings_.settle_revolutions);
  if (s.x_m.size() < settle + 8 * per_rev) return h;  // too short to judge
  milling::CutSettings cs = settings_for(s.head.requested_rpm, s.head.axial_mm);
  milling::CutRecord rec;
  rec.rpm = cs.rpm, rec.step_s = plant_.period_s(), rec.teeth = cutter_.teeth;
  rec.steps_per_tooth = m, rec.settle_steps = settle;
  rec.x_m = s.x_m, rec.y_m = s.y_m;
  const double fs = 1.0 / plant_.period_s();
  const std::vector<double> tones = forced_tones(drive_hz_, cs.rpm * cutter_.teeth / 60.0, 0.5 * fs);
  remove_tones(rec.x_m, settle, fs, tones);
  remove_tones(rec.y_m, settle, fs, tones);
  rec.engaged_samples = s.engaged, rec.out_of_cut_samples = s.out_of_cut;
  h.verdict = milling::classify(std::move(rec), cs).verdict;
  h.judged = true;
  return h;
}

RegenerativeCutReport RegenerativeCut::report() const {
  RegenerativeCutReport r = rep_;
  r.requested_rpm = requested_rpm_, r.rpm = settings_.rpm, r.axial_mm = settings_.cut.axial_mm;
  r.steps_per_tooth = settings_.steps_per_tooth;
  if (!started_) return r;
  for (const Segment& s : segments_) r.segments.push_back(judged(s));
  if (!r.complete) r.end_s = t_s_;
  const CutSegment& last = r.segments.back();
  if (last.judged)
    r.verdict = last.verdict;
  else
    r.complete = false;  // the cut's end too short to judge
  r.sle_um = process_->sle_um();
  return r;
}

namespace {

nlohmann::json segments_json(const std::vector<CutSegment>& segments) {
  nlohmann::json out = nlohmann::json::array();
  auto time_or_null = [](double t) { return t >= 0.0 ? nlohmann::json(t) : nlohmann::json(nullptr); };
  for (const CutSegment& s : segments) {
    const auto& v = s.verdict;
    out.push_back(
        {{"cause", s.cause},
         {"start_s", s.start_s},
         {"end_s", s.end_s},
         {"requested_rpm", s.requested_rpm},
         {"rpm", s.rpm},
         {"axial_mm", s.axial_mm},
         {"revolutions", s.revolutions},
         {"classification", s.judged ? milling::to_string(v.classification) : "too short"},
         {"stable", s.judged ? nlohmann::json(v.stable) : nlohmann::json(nullptr)},
         {"chatter_hz", s.judged && v.chatter_hz > 0.0 ? nlohmann::json(v.chatter_hz) : nlohmann::json(nullptr)},
         {"growth_per_tooth", s.judged ? nlohmann::json(v.growth_per_period) : nlohmann::json(nullptr)},
         {"nonharmonic_energy_ratio", s.judged ? nlohmann::json(v.nonharmonic_energy_ratio) : nlohmann::json(nullptr)},
         {"indicator_chatter_s", time_or_null(s.indicator_chatter_s)},
         {"indicator_quiet_s", time_or_null(s.indicator_quiet_s)}});
  }
  return out;
}

}  // namespace

nlohmann::json regenerative_cut_json(const RegenerativeCutReport& r) {
  if (!r.cut) return nullptr;
  const auto& v = r.verdict;
  return {{"job", r.job},
          {"model", "regenerative"},
          {"requested_rpm", r.requested_rpm},
          {"rpm", r.rpm},
          {"axial_mm", r.axial_mm},
          {"radial_mm", r.radial_mm},
          {"teeth", r.teeth},
          {"steps_per_tooth", r.steps_per_tooth},
          {"revolutions", r.revolutions},
          {"settle_revolutions", r.settle_revolutions},
          {"start_s", r.start_s},
          {"end_s", r.end_s},
          {"complete", r.complete},
          {"stable", r.complete && v.stable},
          {"classification", r.complete ? milling::to_string(v.classification) : "incomplete"},
          {"mechanism", milling::to_string(v.mechanism)},
          {"chatter_hz", v.chatter_hz > 0.0 ? nlohmann::json(v.chatter_hz) : nlohmann::json(nullptr)},
          {"growth_per_tooth", v.growth_per_period},
          {"nonharmonic_energy_ratio", v.nonharmonic_energy_ratio},
          {"once_per_tooth_ratio", v.once_per_period_ratio},
          {"out_of_cut_share", v.out_of_cut_share},
          {"peak_force_n", r.peak_force_n},
          {"sle_um", r.sle_um},
          {"segments", segments_json(r.segments)}};
}

}  // namespace robodamp::hil
