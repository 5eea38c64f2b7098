// `robodamp identify cutting`: cutting coefficients of a flat end mill from mean forces at several feeds,
// with their 95 % confidence intervals and the fit's quality figures, as JSON and as a `material:` block
// for milling jobs. `robodamp identify modes`: the modes of a measured FRF (LSCF poles with a stabilisation
// diagram, LSFD residues, a nonlinear refinement) as JSON, a `modes:` list for presets and milling jobs,
// and plots. docs/identification.md.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "apps/cli.hpp"
#include "apps/identify_command.hpp"
#include "identify/modal_fit_report.hpp"

namespace robodamp::apps {

bool print_identified(const IdentifyArgs& a, const std::string& text, const nlohmann::json& report_json,
                      const std::string& yaml) {
  std::fputs(text.c_str(), stdout);
  if (a.json.given) {
    if (!emit_json(a.json, report_json.dump(2), "identify")) return false;
    if (a.json.to_file()) std::printf("wrote %s\n", a.json.path.c_str());
  }
  if (!a.yaml_path.empty()) {
    std::ofstream(a.yaml_path) << yaml;
    std::printf("wrote %s\n", a.yaml_path.c_str());
  }
  return true;
}

namespace {

int run_modes(const IdentifyArgs& a) {
  identify::ModalFitSettings s;
  if (a.band_hz.size() == 2) s.band_lo_hz = a.band_hz[0], s.band_hi_hz = a.band_hz[1];
  s.max_order = a.max_order.value_or(40);
  identify::FrfData d;
  identify::ModalFit fit;
  try {
    if (!a.band_hz.empty() && (a.band_hz.size() != 2 || !(a.band_hz[1] > a.band_hz[0])))
      throw std::invalid_argument("--band-hz: two frequencies, LO < HI");
    if (a.frf_path.empty() == a.series_path.empty())
      throw std::invalid_argument("give either --frf (an FRF) or --series (force and response in time)");
    identify::FrfRead read = identify::read_frf_source(
        {a.frf_path, a.series_path, a.record, a.response, a.reference, a.kind, a.segment_s, a.overlap, a.band_hz});
    std::fputs(read.note.c_str(), stdout);
    d = std::move(read.data);
    fit = identify::fit_modes(d, s);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify modes: " << e.what() << '\n';
    return 2;
  }
  const identify::ModalFitReport r = identify::modal_fit_report(fit, a.frf_path);
  if (!print_identified(a, r.text, r.json, r.yaml)) return 1;
  if (!a.plot_dir.empty()) {
    if (auto e = identify::plot_modal_fit(d, fit, a.plot_dir, "modes"); !e.empty()) {
      std::cerr << "plot: " << e << '\n';
      return 1;
    }
    std::printf("wrote plots in %s\n", a.plot_dir.c_str());
  }
  return 0;
}

int run_identify(const IdentifyArgs& a) {
  if (a.what == "modes") return run_modes(a);
  if (a.what == "actuator") return run_identify_actuator(a);
  if (a.what == "all") return run_identify_all(a);
  if (a.ball_end) return run_identify_ball_end(a);
  return run_identify_cutting(a);
}

}  // namespace

namespace {
void add_cutting_options(Registry& r, CLI::App* sub, IdentifyArgs& a);
void add_other_options(Registry& r, CLI::App* sub, IdentifyArgs& a);
}  // namespace

void register_identify(Registry& r) {
  auto a = std::make_shared<IdentifyArgs>();
  CLI::App* sub =
      r.add("identify",
            "Identify from measurements: `identify modes` (modes of an FRF), `identify actuator` (Eq. 3 from a "
            "chirp), `identify all` (a configuration from a `measure` directory), `identify cutting` "
            "(cutting coefficients from mean forces)",
            [a] { return run_identify(*a); });
  sub->add_option("what", a->what, "What to identify: modes, actuator, all or cutting")
      ->required()
      ->check(CLI::IsMember({"modes", "actuator", "all", "cutting"}));
  sub->add_option(
         "--frf", a->frf_path,
         "modes: an FRF table freq_hz,re_m_per_n,im_m_per_n[,coherence] (any delimiter, decimal comma, header or none) "
         "or a universal file (dataset 58/58b; its header gives the kind and the units)")
      ->check(CLI::ExistingFile);
  r.whole_number(sub, "--record", a->record, {"(record)", 1, 1000000},
                 "modes: the universal file's Nth function record");
  sub->add_option("--reference", a->reference,
                  "modes: the universal file's record by its reference DOF NODE:DIR (e.g. 2:+Y)");
  sub->add_option("--series", a->series_path, "modes: time series CSV time_s,force_n,response (H1 by Welch)")
      ->check(CLI::ExistingFile);
  sub->add_option(
      "--response", a->response,
      "modes: the --series response (acceleration, velocity, displacement), or a universal file's record by its "
      "response DOF NODE:DIR (e.g. 1:+Y)");
  r.number(sub, "--segment-s", a->segment_s, {"s", 0.0, 1e5, true, false},
           "modes, actuator: Welch segment length for --series / --csv");
  r.number(sub, "--overlap", a->overlap, {"(fraction)", 0.0, 0.9, false, false},
           "modes: Welch segment overlap for --series");
  sub->add_option("--kind", a->kind, "modes: what the FRF CSV holds")
      ->check(CLI::IsMember({"receptance", "mobility", "accelerance"}));
  r.numbers(sub, "--band-hz", a->band_hz, {"Hz", 0.0, 1e6, false, false},
            "modes, actuator: fit band LO HI (default: the whole FRF; actuator: the chirp within analysis.band)");
  r.whole_number(sub, "--max-order", a->max_order, {"(model order)", 4, 200},
                 "modes, all: highest order of the stabilisation diagram (even; default 40 for modes, 60 for all: a "
                 "close pair common to several FRFs separates slowly with the order)");
  r.plot_dir(sub, a->plot_dir, "modes, all: the fits and the stabilisation diagrams");
  add_cutting_options(r, sub, *a);
  add_other_options(r, sub, *a);
}

namespace {

// identify cutting's options: the mean forces or the force records, and the tests' tool and cut.
void add_cutting_options(Registry& r, CLI::App* sub, IdentifyArgs& a) {
  sub->add_option(
         "--csv", a.csv_path,
         "cutting: mean forces feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n; actuator: time_s,command_v,force_n")
      ->check(CLI::ExistingFile);
  sub->add_option(
      "--records", a.records,
      "cutting: force records, one per test (files, or a directory's files in name order): time, Fx, Fy, Fz as a "
      "dynamometer or logger exports them (any delimiter, decimal comma, preamble, units in the header)");
  sub->add_option("--tests", a.tests_path,
                  "cutting: a table of the tests: file, feed_per_tooth_mm, spindle_rpm (files relative to it)")
      ->check(CLI::ExistingFile);
  r.numbers(sub, "--feeds-mm", a.feeds_mm, {"mm", 0.0, 10.0, false, false},
            "cutting --records: the feed per tooth of each record, in order");
  r.number(sub, "--rpm", a.rpm, {"rpm", 0.0, 200000.0, false, false},
           "cutting --records: the spindle speed of the tests");
  sub->add_option("--axes", a.axes,
                  "cutting --records: the cutter's x (feed), y (normal), z (tool axis) from the record's Fx, Fy, Fz, "
                  "e.g. -fy,fx,fz "
                  "(default fx,fy,fz)");
  sub->add_option("--force-on", a.force_on,
                  "cutting --records: what the dynamometer measures the force on (default: workpiece)")
      ->check(CLI::IsMember({"workpiece", "tool"}));
  r.whole_number(sub, "--teeth", a.teeth, {"(teeth)", 1, 32}, "cutting: teeth of the tool");
  r.number(sub, "--diameter-mm", a.diameter_mm, {"mm", 0.0, 200.0, true, false}, "cutting: tool diameter");
  r.number(sub, "--axial-mm", a.axial_mm, {"mm", 0.0, 100.0, true, false}, "cutting: axial depth of the tests");
  r.number(sub, "--radial-mm", a.radial_mm, {"mm", 0.0, 200.0, true, false, "and at most --diameter-mm"},
           "cutting: radial depth of the tests (the diameter: slotting)");
  sub->add_flag("--ball-end", a.ball_end,
                "cutting: a ball-end mill from slot-milling mean forces "
                "axial_mm,feed_per_tooth_mm,fx_mean_n,fy_mean_n,fz_mean_n");
  r.number(sub, "--helix-deg", a.helix_deg, {"deg", 0.0, 89.0},
           "cutting --ball-end: helix angle at the ball's equator");
  r.whole_number(sub, "--order", a.order, {"(polynomial order)", 0, 3},
                 "cutting --ball-end: order of the shear coefficients' polynomial in the axial angle (the ball-end "
                 "bone study: 3)");
  sub->add_option("--mode", a.mode, "cutting: down or up milling")->check(CLI::IsMember({"down", "up"}));
}

// identify actuator's and identify all's options, and the outputs.
void add_other_options(Registry& r, CLI::App* sub, IdentifyArgs& a) {
  sub->add_option("--recording", a.recording_path, "actuator: a robodamp measure recording (the chirp and the sensor)")
      ->check(CLI::ExistingFile);
  sub->add_option("--structure", a.structure_path,
                  "actuator: FRF CSV of the structure at the sensor for a force at the actuator (--kind applies)")
      ->check(CLI::ExistingFile);
  sub->add_option("--in", a.in_dir, "all: the directory robodamp measure wrote")->check(CLI::ExistingDirectory);
  sub->add_option("--out", a.out_path, "all: write the identified configuration (YAML) here");
  sub->add_option("--uff", a.uff_path,
                  "all: a universal file instead of --in: an FRF per force between every pair of locations and the "
                  "actuator's acceleration per volt at the sensor (what measure and commission export)")
      ->check(CLI::ExistingFile);
  sub->add_option("--config", a.config_path, "all --uff: the configuration the measurement ran with")
      ->check(CLI::ExistingFile);
  sub->add_option("--tap-tests", a.tap_tests,
                  "all: with --in, the FRFs between the locations from your modal kit's tap tests (universal files or "
                  "frf_<response>_<excitation>.csv) and the actuator from --in's chirp (robodamp measure --no-hammer); "
                  "refused when they contradict the chirp")
      ->check(CLI::ExistingFile);
  sub->add_option("--modes-uff", a.modes_uff_path,
                  "all: also write the identified modes as a universal file (datasets 15, 55)");
  r.json(sub, a.json, "The result and its quality figures");
  sub->add_option("--yaml", a.yaml_path, "Write a modes: list (modes) or a material: block (cutting)");
}

}  // namespace

}  // namespace robodamp::apps
