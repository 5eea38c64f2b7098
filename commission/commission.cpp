#include "commission/commission.hpp"

#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"

#include "commission/emulated_cell.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "commission/measurement.hpp"
#include "commission/report.hpp"
#include "commission/stage_detail.hpp"
#include "config/milling_config.hpp"
#include "tune/speed_schedule_report.hpp"
#include "tune/tuned_file.hpp"

namespace robodamp::commission {

namespace {

namespace fs = std::filesystem;
using detail::Clock;
using detail::fmt;
using detail::seconds_since;
using detail::Stop;

class Run {
 public:
  Run(const CommissionSettings& s, const std::function<void(const std::string&)>& progress, CommissionResult& r)
      : s_(s), say_(progress), r_(r), dir_(s.out_dir), stage_(s.from, s.out_dir, say_, r.stage, r.times) {}

  void all() {
    fs::create_directories(dir_);
    std::error_code ec;
    fs::remove(dir_ / "configuration.yaml", ec);  // only this run's verified result may stand there
    cell_ = config::load_config_file(s_.config_path);
    real_ = !s_.tap_tests.empty();
    r_.real_cell = real_;
    if (const std::string why = hardware_refusal(cell_); !why.empty() && !real_)
      throw Stop{Stage::kMeasure, Outcome::kBadInput, why};
    emulated_ = cell_.can && cell_.can->interface.rfind("unix:", 0) == 0;
    if (emulated_) {
      binary_ = s_.robodamp_binary.empty() ? this_executable() : s_.robodamp_binary;
      say_("commission: the cell is the HIL emulator on " + cell_.can->interface +
           ": `robodamp plant` runs as a second process for each run on the cell (lockstep)" +
           (real_ ? ", told it is a real cell: no impacts, no cut" : ""));
    }
    if (real_)
      say_(
          "commission: a real cell: the actuator is the shaker (its chirp, control off then on), the FRFs between the "
          "locations come from " +
          std::to_string(s_.tap_tests.size()) +
          " tap-test file(s); robodamp orders no hammer "
          "blow and no cut");
    job_ = config::load_milling_config(s_.job_path);
    stage_(Stage::kMeasure, [this] { measure(); });
    stage_(Stage::kIdentify, [this] { identify(); });
    stage_(Stage::kTune, [this] { tune(); });
    stage_(Stage::kVerify, [this] { verify(); });
    stage_(Stage::kWrite, [this] { write(); });
  }

 private:
  void measure() {
    const fs::path m = dir_ / "measurement";
    if (!stage_.reuse()) {
      MeasureOptions mo;
      mo.impacts = !real_;
      const MeasureOutcome o = emulated_
                                   ? measure_through_emulator(s_.config_path, m.string(), binary_, {mo, std::nullopt})
                                   : commission::measure(s_.config_path, m.string(), mo);
      // The measurement turns SIGINT / SIGTERM into a trip of its loop; the stages after it have no loop
      // to stop, so the signals end the process again (nothing half-written: the result is renamed into
      // place at the end).
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
      detail::throw_unless_measured(o, Stage::kMeasure);
      say_(
          fmt("commission: measured %d of %d impact records, chirp active over %.1f %% of its ticks, peak command "
              "%.3f V, the cell at rest at %.4f m/s^2 RMS before it",
              o.impact_records, o.impact_records_planned, 100.0 * o.chirp_active_share, o.peak_command_v,
              o.rest_accel_rms_mps2));
    } else if (!fs::exists(m / identify::kManifestName)) {
      throw Stop{Stage::kMeasure, Outcome::kBadInput,
                 "--from " + std::string(to_string(s_.from)) + ": " + (m / identify::kManifestName).string() +
                     " does not exist: run from measure"};
    }
  }

  void identify() {
    const identify::MeasurementManifest man = identify::read_manifest((dir_ / "measurement").string());
    const auto sat = man.run.value("saturated_ticks", 0ULL);
    if (sat > 0)
      throw Stop{Stage::kIdentify, Outcome::kBadInput,
                 "the chirp saturated the actuator over " + std::to_string(sat) +
                     " ticks: the measurement is not linear; lower commissioning.chirp_force_fraction"};
    identify::CommissioningSettings cs;
    identify::TapTests taps;
    const identify::CommissioningInputs inputs =
        real_ ? identify::inputs_with_tap_tests((dir_ / "measurement").string(), s_.tap_tests, taps)
              : identify::read_measurement_dir((dir_ / "measurement").string());
    r_.identified = identify::identify_all(inputs, cs);
    const auto& id = *r_.identified;
    if (real_) {
      r_.tap_check = identify::check_tap_tests(inputs, id, taps, s_.tap_tolerance_pct);
      say_("commission: the tap tests against the actuator's chirp: " + r_.tap_check->summary());
      if (const std::string f = r_.tap_check->failure(); !f.empty())
        throw Stop{Stage::kIdentify, Outcome::kBadInput, f};
    }
    std::ofstream(dir_ / "identified.yaml") << id.yaml;
    std::ofstream(dir_ / "identified.json") << identify::to_json(id).dump(2) << '\n';
    // What a modal package opens: every FRF measured with its coherence, and the identified modes.
    measfiles::write_uff((dir_ / "measurement" / identify::kMeasurementUffName).string(),
                         identify::measurement_to_uff(inputs), measfiles::UffEncoding::kAscii);
    measfiles::write_uff((dir_ / identify::kModesUffName).string(), identify::modes_to_uff(id),
                         measfiles::UffEncoding::kAscii);
    say_("commission: identified " + std::to_string(id.frfs.size()) + " FRFs; " +
         fmt("actuator T %.3f N/V, %.3f Hz, zeta %.4f, delay %.3f ms", id.actuator.force_constant_n_per_v,
             id.actuator.natural_freq_hz, id.actuator.damping_ratio, id.actuator.delay_ms));
    for (const auto& f : id.frfs)
      say_("commission:   " + f.name + ": " + std::to_string(f.fit.modes.size()) + " modes, " +
           fmt("fit error %.2f %%", f.fit.fit_error_pct));
    if (s_.shift_pct) {
      r_.shift_pct = *s_.shift_pct;
      r_.shift_reason = "given (--shift-pct)";
    } else {
      std::tie(r_.shift_pct, r_.shift_reason) = modal_uncertainty_pct(id, s_.min_shift_pct, s_.max_shift_pct);
    }
    say_(fmt("commission: the tune is robust over the modes shifted by +-%.2f %%: ", r_.shift_pct) + r_.shift_reason);
  }

  // The identified plant (the objective: the job's damped limits) and, as constraints only (stable, the
  // margins, every mode damped, the actuator's limits), the same with its modes shifted down and up.
  std::vector<tune::Evaluator> plants() const {
    const config::Config& base = r_.identified->config;
    std::vector<tune::Evaluator> p;
    p.emplace_back(base, job_, s_.tune, "identified");
    for (const double sign : {-1.0, 1.0}) {
      p.emplace_back(tune::with_shifted_modes(base, 1.0 + sign * r_.shift_pct / 100.0), std::nullopt, s_.tune,
                     fmt("identified, modes %+.2f %%", sign * r_.shift_pct));
      p.back().set_constraints_only(true);
    }
    return p;
  }

  void tune() {
    const std::vector<tune::Evaluator> p = plants();
    std::vector<const tune::Evaluator*> refs;
    for (const auto& e : p) refs.push_back(&e);
    r_.open_curve_mm = p.front().open_curve_mm();
    const fs::path tuned_path = dir_ / "tuned.yaml";
    if (stage_.reuse()) {
      if (!fs::exists(tuned_path))
        throw Stop{Stage::kTune, Outcome::kBadInput,
                   "--from verify: " + tuned_path.string() + " does not exist: run from tune"};
      r_.tuned_config = config::load_config_file(tuned_path.string());
      r_.tuned_nominal = p.front().assess(*r_.tuned_config);
      r_.tuned = r_.tuned_nominal;
      if (const tune::Evaluation& e = *r_.tuned_nominal; !e.stable)
        throw Stop{Stage::kTune, Outcome::kBadInput,
                   tuned_path.string() +
                       fmt(": its loop is unstable on the identified model (K = %.0f N s/m, polarity %+d; ",
                           e.candidate.gain_ns_per_m, e.candidate.polarity) +
                       (std::isfinite(e.k_max_ns_per_m) ? fmt("the largest stable K is %.0f N s/m)", e.k_max_ns_per_m)
                                                        : std::string("no gain is stable with this polarity)")) +
                       ": run from tune"};
      schedule();
      return;
    }
    const tune::TuneResult t = tune::tune(refs, s_.tune, [this](const std::string& l) { say_("commission: " + l); });
    r_.tuned = t.best;
    if (!t.best.feasible())
      throw Stop{Stage::kTune, Outcome::kNotVerified,
                 "no candidate met every constraint; the closest violates " + t.best.binding};
    r_.tuned_nominal = t.best.per_plant.empty() ? t.best : t.best.per_plant.front();
    const config::EditedYaml edited = tune::tuned_config_text(r_.identified->config, t.best.candidate);
    const std::string text =
        "# robodamp commission tuned this (docs/identification.md) from the identified cell:\n#   " + s_.command_line +
        "\n#\n" + edited.text;
    r_.tuned_config = config::parse_config(text, tuned_path.string());
    std::ofstream(tuned_path) << text;
    say_(
        fmt("commission: tuned K %.0f N s/m, polarity %+d; worst over the plants GM %.1f dB, PM %.1f deg, the command "
            "on a quiet cell %.4f V RMS (the instability detector's floor %.3f V)",
            t.best.candidate.gain_ns_per_m, t.best.candidate.polarity, t.best.gain_margin_db, t.best.phase_margin_deg,
            t.best.quiet_command_rms_v, r_.identified->config.supervision.instability_floor_v));
    schedule();
  }

  // The speed schedule over the job's range: the tuned controller and C1 and C2 drawn in the identified chain
  // (their polarity the analysis recommends), each at the gains that keep the tune's margins; K = 0 where none
  // beats the open loop. Never worse than the open loop at the speeds checked, or the commissioning stops.
  void schedule() {
    const config::Config& tuned = *r_.tuned_config;
    r_.robustness = tune::robustness(tuned);
    const tune::Robustness& rb = *r_.robustness;
    say_(fmt("commission: the tuned loop stays stable and damps its modes from %.1f %% to +%.1f %% of mode shift",
             -rb.down.pct, rb.up.pct) +
         (rb.down.reason.empty() ? "" : "; " + rb.down.reason) + (rb.up.reason.empty() ? "" : "; " + rb.up.reason) +
         (rb.pct() < tune::kRobustShiftWarnPct
              ? fmt(" (WARNING: under +-%.0f %%: a pose or tool change may move the modes further)",
                    tune::kRobustShiftWarnPct)
              : ""));
    std::vector<tune::NamedController> hand;
    for (const auto model : {config::CompensatorModel::kC1, config::CompensatorModel::kC2}) {
      config::Config c = tuned;
      for (auto& b : c.controller.chain)
        if (b.kind == config::BlockKind::kCompensator) b.model = model, b.numerator.clear(), b.denominator.clear();
      c.controller.polarity = analysis::analyse(analysis::LoopModel(c)).recommended_polarity;
      hand.push_back(
          {std::string(config::to_string(model)) + " drawn in the identified chain", config::speed_controller_of(c)});
    }
    tune::ScheduleSettings ss;
    ss.speeds = s_.schedule_speeds;
    ss.gains_per_controller = s_.schedule_gains;
    ss.gain_margin_min_db = s_.tune.gain_margin_min_db;
    ss.phase_margin_min_deg = s_.tune.phase_margin_min_deg;
    ss.delay_margin_min_ms = s_.tune.delay_margin_min_ms;
    const auto t0 = Clock::now();
    r_.schedule = tune::schedule_speeds(tuned, hand, job_, job_.selected_structure(), ss);
    const tune::ScheduleSummary& m = r_.schedule->summary;
    say_(fmt(
        "commission: speed schedule, %zu bands over %zu speeds: minimum %.3f mm (open loop %.3f, the tuned controller "
        "alone %.3f), mean x%.3f the open loop (alone x%.3f), worse than the open loop at %.1f %% (alone %.1f %%); %zu "
        "of %zu damped limits chattered in time (another candidate runs there, or the same at its limit in time; bands "
        "with a depth limit: %zu) (%.1f s)",
        r_.schedule->bands.size(), m.speeds, m.scheduled_min_mm, m.open_min_mm, m.fixed_min_mm, m.scheduled_mean_ratio,
        m.fixed_mean_ratio, 100.0 * m.scheduled_worse_share, 100.0 * m.fixed_worse_share, r_.schedule->lowered_in_time,
        r_.schedule->limits_in_time, r_.schedule->limited_bands(), seconds_since(t0)));
    if (m.scheduled_worse_share > 0.0)
      throw Stop{
          Stage::kTune, Outcome::kNotVerified,
          fmt("the speed schedule is worse than the open loop at %.1f %% of the speeds (the worst x%.3f at %.0f rpm)",
              100.0 * m.scheduled_worse_share, m.scheduled_worst_ratio, m.scheduled_worst_rpm)};
    const std::string text = tune::scheduled_config_text(tuned, *r_.schedule).text;
    r_.scheduled_config = config::parse_config(text, (dir_ / "scheduled.yaml").string());
    std::ofstream(dir_ / "scheduled.yaml") << text;
  }

  void verify() {
    const auto t0 = Clock::now();
    r_.promise = tune::verify(*r_.tuned_config, job_);
    const tune::Verification& v = *r_.promise;
    say_(
        fmt("commission: promise (%s, identified model): damped minimum %.3f mm at %.1f rpm, %.3f mm at the job's "
            "%.1f rpm; the time-domain cut there %.3f / %.3f mm (%.1f s)",
            v.method.c_str(), v.min_depth_mm, v.min_rpm, v.depth_at_speed_mm, v.speed_rpm, v.time_domain_at_min_mm,
            v.time_domain_at_speed_mm, seconds_since(t0)));
    if (!v.time_domain_agrees())
      throw Stop{Stage::kVerify, Outcome::kNotVerified,
                 "on the identified model the time-domain cut disagrees with the " + v.method + " by more than 5 %"};
    if (real_) return verify_real_cell();
    r_.cell = emulated_ ? check_through_emulator(cell_, *r_.tuned_config, v,
                                                 {binary_, s_.config_path, s_.job_path, (dir_ / "measurement").string(),
                                                  (dir_ / "verify").string(), s_.cut_revolutions})
                        : check_on_cell(cell_, *r_.tuned_config, job_, v);
    const CellCheck& c = *r_.cell;
    for (const auto& f : c.frfs)
      say_("commission: on the cell " + f.name +
           fmt(": improvement %.1f %% measured, %.1f %% predicted (coherence >= %.3f)", f.measured_improvement_pct,
               f.predicted_improvement_pct, f.coherence_min));
    say_("commission: on " + c.cell + ": " + c.cut_summary(v));
    if (const std::string f = c.failure(v); !f.empty()) throw Stop{Stage::kVerify, Outcome::kNotVerified, f};
    verify_schedule_in_time();
  }

  // The schedule in time on the identified model, with the real supervisor: the spindle through up to six
  // speeds where the schedule damps (K > 0), spread over the range, the job's speed among them (changed out of
  // the cut), a cut at 0.95 x the scheduled limit at each. Bands at K = 0 carry the open loop's own limit.
  void verify_real_cell() {
    const auto& id = *r_.identified;
    std::vector<double> modes_hz;
    for (const auto& m :
         identify::path_between(id.frfs, id.manifest.sensor_location_id, id.manifest.actuator_location_id).fit.modes)
      modes_hz.push_back(m.natural_freq_hz);
    MeasureOutcome on;
    r_.real_check = verify_on_real_cell(cell_, *r_.tuned_config, modes_hz,
                                        {s_.config_path, (dir_ / "measurement").string(), (dir_ / "verify").string(),
                                         emulated_ ? binary_ : std::string()},
                                        on);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    detail::throw_unless_measured(on, Stage::kVerify);
    const RealCellCheck& c = *r_.real_check;
    for (const auto& line : c.progress_lines()) say_("commission: " + line);
    if (const std::string f = c.failure(); !f.empty()) throw Stop{Stage::kVerify, Outcome::kNotVerified, f};
    verify_schedule_in_time();
  }

  void verify_schedule_in_time() {
    if (!r_.schedule) return;
    std::vector<tune::ScheduleSpeed> damped;
    for (const auto& p : r_.schedule->speeds)
      if (r_.schedule->candidates[p.candidate].gain_ns_per_m > 0.0) damped.push_back(p);
    if (damped.empty()) return;
    std::vector<tune::ScheduledCutStep> steps;
    const std::size_t n = std::min<std::size_t>(5, damped.size());
    for (std::size_t i = 0; i < n; ++i) {
      const auto& p = damped[(damped.size() - 1) * (2 * i + 1) / (2 * n)];
      steps.push_back({p.rpm, 0.95 * p.scheduled_mm});
    }
    const double job_rpm = r_.schedule->summary.job_rpm;
    if (const auto at = config::speed_band_of(r_.schedule->bands, job_rpm);
        job_rpm > 0.0 && at && r_.schedule->bands[*at].gain_ns_per_m > 0.0)
      steps.push_back({job_rpm, 0.95 * r_.schedule->summary.job_scheduled_mm});
    const auto t0 = Clock::now();
    // As many revolutions as the schedule's own check in time (the job's): fewer read a slow decay near the limit as chatter.
    r_.schedule_in_time = tune::scheduled_cut(*r_.scheduled_config, job_, steps, job_.time_domain.revolutions);
    const tune::ScheduledCut& c = *r_.schedule_in_time;
    for (const auto& s : c.segments)
      say_(
          fmt("commission: the schedule in time at %.1f rpm, %.3f mm (0.95 x its limit): %s; the switch %.2f N, the "
              "cut %.1f N "
              "of the actuator's %.0f N",
              s.rpm, s.depth_mm, milling::to_string(s.verdict.classification), s.switch_peak_force_n,
              s.peak_force_command_n, c.force_limit_n));
    say_(fmt("commission: the schedule in time: %.1f s", seconds_since(t0)));
    if (!c.all_stable() || !c.switches_within_limits())
      throw Stop{
          Stage::kVerify, Outcome::kNotVerified,
          "the speed schedule in time: a cut at 0.95 x its limit chattered, or a switch drove the actuator to a limit"};
  }

  void write() {
    const tune::Verification& v = *r_.promise;
    std::ostringstream h;
    h << "# robodamp commission wrote this (docs/identification.md) for the cell " << s_.config_path << " and the job "
      << s_.job_path << ":\n#   " << s_.command_line << "\n";
    h << fmt("# Promised (%s, identified model): damped minimum %.3f mm at %.1f rpm, %.3f mm at the job's %.1f rpm.\n",
             v.method.c_str(), v.min_depth_mm, v.min_rpm, v.depth_at_speed_mm, v.speed_rpm)
      << verified_on_text();
    if (r_.tuned_nominal)
      h << fmt(
          "\n# On a quiet cell the command is %.4f V RMS (the discrete loop's prediction; the instability "
          "detector's floor %.3f V).",
          r_.tuned_nominal->quiet_command_rms_v, r_.tuned_config->supervision.instability_floor_v);
    h << "\n";
    if (r_.schedule) h << tune::schedule_header(*r_.schedule);
    h << "#\n";
    r_.configuration_path = detail::write_configuration(dir_, (r_.schedule ? "scheduled.yaml" : "tuned.yaml"), h.str());
  }

  // The configuration's header line: what was checked on the cell itself.
  std::string verified_on_text() const {
    std::ostringstream h;
    if (r_.real_check) return r_.real_check->header_lines();
    const CellCheck& c = *r_.cell;
    h << "# Verified on " << c.cell << ": " << c.cut_summary(*r_.promise) << ";";
    for (const auto& f : c.frfs)
      h << " " << f.name
        << fmt(" improvement %.1f %% measured, %.1f %% predicted;", f.measured_improvement_pct,
               f.predicted_improvement_pct);
    return h.str();
  }

  const CommissionSettings& s_;
  const std::function<void(const std::string&)>& say_;
  CommissionResult& r_;
  fs::path dir_;
  detail::StageRunner stage_;
  config::Config cell_;
  config::MillingConfig job_;
  bool emulated_{false};  // the cell is the HIL emulator (a can: section with a unix: interface)
  bool real_{false};      // a real cell: tap tests in place of robodamp's hammer, no cut
  std::string binary_;    // robodamp, for the emulator's process
};

}  // namespace

const char* to_string(Stage s) {
  switch (s) {
    case Stage::kMeasure:
      return "measure";
    case Stage::kIdentify:
      return "identify";
    case Stage::kTune:
      return "tune";
    case Stage::kVerify:
      return "verify";
    case Stage::kWrite:
      return "write";
  }
  return "?";
}

Stage stage_from_string(const std::string& s) {
  for (const Stage st : {Stage::kMeasure, Stage::kIdentify, Stage::kTune, Stage::kVerify})
    if (s == to_string(st)) return st;
  throw std::invalid_argument("--from = '" + s + "': allowed measure, identify, tune, verify");
}

int exit_code(Outcome o) {
  switch (o) {
    case Outcome::kVerified:
      return 0;
    case Outcome::kBadInput:
      return 2;
    case Outcome::kNotVerified:
      return 3;
    case Outcome::kTripped:
      return 4;
    case Outcome::kFailed:
      return 1;
    case Outcome::kRefused:
      return 6;
    case Outcome::kAborted:
      return 8;
  }
  return 1;
}

std::pair<double, std::string> modal_uncertainty_pct(const identify::CommissioningResult& r, double min_pct,
                                                     double max_pct) {
  double worst = 0.0;
  std::string which = "every mode agrees across the FRFs";
  if (!r.frfs.empty())
    for (const auto& m : r.frfs.front().fit.modes) {
      double lo = m.natural_freq_hz, hi = m.natural_freq_hz;
      int seen = 1;
      for (std::size_t i = 1; i < r.frfs.size(); ++i) {  // the same mode: the nearest one, within 5 %
        const identify::IdentifiedMode* near = nullptr;
        for (const auto& o : r.frfs[i].fit.modes)
          if (!near ||
              std::abs(o.natural_freq_hz - m.natural_freq_hz) < std::abs(near->natural_freq_hz - m.natural_freq_hz))
            near = &o;
        if (near && std::abs(near->natural_freq_hz / m.natural_freq_hz - 1.0) < 0.05)
          lo = std::min(lo, near->natural_freq_hz), hi = std::max(hi, near->natural_freq_hz), ++seen;
      }
      const double spread = (hi - lo) / m.natural_freq_hz * 100.0;
      if (seen > 1 && spread > worst) {
        worst = spread;
        which = fmt("the %.3f Hz mode spreads %.3f %% over the FRFs", m.natural_freq_hz, spread);
      }
    }
  const double pct = std::clamp(3.0 * worst, min_pct, max_pct);
  return {pct, which + fmt(" (3 x the spread, within %.1f-%.1f %%)", min_pct, max_pct)};
}

CommissionResult commission(const CommissionSettings& s, const std::function<void(const std::string&)>& progress) {
  CommissionResult r;
  const auto t0 = Clock::now();
  detail::run_to_outcome(r, [&] { Run(s, progress, r).all(); });
  r.wall_s = seconds_since(t0);
  r.report_path = (fs::path(s.out_dir) / "report.html").string();
  std::error_code ec;
  if (fs::is_directory(s.out_dir, ec)) {
    if (const std::string e = write_report(s, r, r.report_path); !e.empty()) {
      progress("commission: the report: " + e);
      r.report_path.clear();
    }
  } else {
    r.report_path.clear();
  }
  return r;
}

}  // namespace robodamp::commission
