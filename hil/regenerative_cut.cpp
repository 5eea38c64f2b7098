#include "hil/regenerative_cut.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "analysis/loop_model.hpp"
#include "milling/cut_job.hpp"
#include "milling/cut_stability.hpp"
#include "milling/damped_dynamics.hpp"
#include "milling/structure.hpp"

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
  for (const double f : freqs_hz) rot.push_back(std::polar(1.0, 2.0 * M_PI * f / fs));
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

}  // namespace

RegenerativeCut::RegenerativeCut(const config::Config& cfg, sim::Plant& plant, const RegenerativeCutOptions& o)
    : plant_(plant) {
  const config::MillingConfig job = config::load_milling_config(o.job_path);
  // The job's structure with its controller part on this cell: the part's location and direction are where
  // the cut acts on the plant; its loop rate is the cut's step.
  const milling::Structure structure(job.selected_structure(), false,
                                     {std::make_shared<const analysis::LoopModel>(cfg), cfg.controller.gain_ns_per_m,
                                      cfg.controller.polarity});
  if (structure.controller_parts().empty())
    throw config::ConfigError({{job.source, {}, "structures." + job.structure,
                                "the emulator's cut acts on the robot at the structure's controller part; structures." +
                                    job.structure + " has none"}});
  milling::CutOverrides co;
  co.rpm = o.rpm, co.axial_mm = o.axial_mm, co.damped = true;
  co.revolutions = o.revolutions.value_or(std::max(job.time_domain.revolutions, kMinRevolutions));
  const milling::CutJob cj = milling::make_cut_job(job, structure, co);
  cutter_ = cj.cutter, material_ = cj.material, settings_ = cj.settings;
  feed_ = job.cut.feed_axis;
  const auto& part = structure.controller_parts().front();
  location_ = part.location, direction_ = part.direction;
  process_.emplace(cutter_, material_, settings_);
  const milling::Structure tables(structure.modal_terms_by_pair(), structure.name());
  if (const auto terms = milling::cutter_modal_terms(tables, feed_); !terms.empty())
    tables_ = std::make_unique<milling::ToolDynamics>(terms, plant.period_s());
  auto force = std::make_unique<sim::HeldForce>(location_);
  force_ = force.get();
  plant_.add_excitation(std::move(force));
  steps_ = process_->steps_per_revolution() * static_cast<std::size_t>(settings_.revolutions);
  x_m_.reserve(steps_), y_m_.reserve(steps_);
  auto_delay_s_ = cfg.hil.settle_s + cfg.controller.gain_ramp_s;
  // The robot's own vibration with the drives on is a forced motion at its frequency and, through the
  // cut's tooth-periodic force, at that frequency +- the tooth harmonics: not the cut's regeneration.
  if (cfg.disturbances.drives_on && cfg.disturbances.drive_vibration_hz > 0.0) {
    const double fd = cfg.disturbances.drive_vibration_hz, ft = settings_.rpm * cutter_.teeth / 60.0;
    for (int h = 1; h <= kForcedHarmonics; ++h)
      for (int k = -kForcedSidebands; k <= kForcedSidebands; ++k) {
        const double f = std::abs(h * fd + k * ft);
        const double to_harmonic = std::abs(f / ft - std::round(f / ft)) * ft;  // the cut's own harmonics stay
        const bool seen = std::any_of(forced_hz_.begin(), forced_hz_.end(), [f](double g) { return std::abs(g - f) < 1e-9; });
        if (f > 0.0 && f < 0.5 / plant.period_s() && to_harmonic > 1e-6 && !seen) forced_hz_.push_back(f);
      }
  }
  rep_.cut = true;
  rep_.job = o.job_path;
  rep_.requested_rpm = cj.requested_rpm, rep_.rpm = settings_.rpm;
  rep_.axial_mm = settings_.cut.axial_mm, rep_.radial_mm = settings_.cut.radial_mm;
  rep_.teeth = cutter_.teeth, rep_.steps_per_tooth = settings_.steps_per_tooth;
  rep_.revolutions = settings_.revolutions, rep_.settle_revolutions = settings_.settle_revolutions;
  rep_.start_s = o.start_s;
}

void RegenerativeCut::amplifier_ready(double t_s) {
  if (rep_.start_s < 0.0) rep_.start_s = t_s + auto_delay_s_;
}

Eigen::Vector2d RegenerativeCut::displacement() const {
  Eigen::Vector2d machine = Eigen::Vector2d::Zero();
  machine(static_cast<Eigen::Index>(direction_)) = plant_.displacement_m(location_);
  return milling::to_cutter(machine, feed_) + (tables_ ? tables_->displacement() : Eigen::Vector2d::Zero());
}

void RegenerativeCut::before_step(double t_s) noexcept {
  force_->value_n = 0.0;
  if (!started_) {
    if (rep_.start_s < 0.0 || t_s < rep_.start_s) return;
    started_ = true;
    previous_ = last_ = displacement();
  }
  if (k_ >= steps_) return;
  // As the in-process cut: the displacement at the step's middle from its start and a linear look-ahead.
  const Eigen::Vector2d q = displacement(), q_end = 2.0 * last_ - previous_;
  const std::size_t settle = process_->steps_per_revolution() * static_cast<std::size_t>(settings_.settle_revolutions);
  const bool stats = k_ >= settle;
  f_ = process_->force(k_, 0.5 * (q + q_end), stats);
  if (stats) rep_.peak_force_n = std::max(rep_.peak_force_n, f_.norm());
  x_m_.push_back(q(0)), y_m_.push_back(q(1));
  q_start_ = q;
  force_->value_n = milling::to_machine(f_, feed_)(static_cast<Eigen::Index>(direction_));
}

void RegenerativeCut::after_step() noexcept {
  if (!started_ || k_ >= steps_) return;
  if (tables_) tables_->step(f_);
  previous_ = last_;
  last_ = displacement();
  process_->end_step(q_start_, last_);
  if (++k_ == steps_) rep_.complete = true, rep_.end_s = rep_.start_s + static_cast<double>(steps_) * plant_.period_s();
}

RegenerativeCutReport RegenerativeCut::report() const {
  RegenerativeCutReport r = rep_;
  if (!started_) return r;
  if (!r.complete) r.end_s = r.start_s + static_cast<double>(k_) * plant_.period_s();
  const std::size_t per_rev = process_->steps_per_revolution();
  const std::size_t settle = per_rev * static_cast<std::size_t>(settings_.settle_revolutions);
  if (x_m_.size() < settle + 8 * per_rev) return r;  // too short to judge (the verdict stays default: see complete)
  milling::CutRecord rec;
  rec.rpm = settings_.rpm, rec.step_s = plant_.period_s(), rec.teeth = cutter_.teeth;
  rec.steps_per_tooth = settings_.steps_per_tooth, rec.settle_steps = settle;
  rec.x_m = x_m_, rec.y_m = y_m_;
  remove_tones(rec.x_m, settle, 1.0 / plant_.period_s(), forced_hz_);
  remove_tones(rec.y_m, settle, 1.0 / plant_.period_s(), forced_hz_);
  rec.engaged_samples = process_->engaged_samples(), rec.out_of_cut_samples = process_->out_of_cut_samples();
  r.verdict = milling::classify(std::move(rec), settings_).verdict;
  r.sle_um = process_->sle_um();
  return r;
}

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
          {"sle_um", r.sle_um}};
}

}  // namespace robodamp::hil
