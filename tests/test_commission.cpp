// robodamp commission (commission/commission.hpp): a synthetic robot no preset describes commissioned end to
// end on the simulated plant and verified on the running cell; bad input stopped at its stage with the
// reason and nothing written as configuration.yaml; the report's plotted data checked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "identify/uff_commissioning.hpp"
#include "measfiles/uff.hpp"
#include "commission/command_line.hpp"
#include "commission/commission.hpp"
#include "commission/cell_check.hpp"
#include "commission/measurement.hpp"
#include "config/yaml_edit.hpp"
#include "identify/modal_fit.hpp"
#include "test_util.hpp"
#include "tune/tuned_file.hpp"
#include "yaml_style.hpp"
#include "tune/compensator_search.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;

std::string cell(const std::string& name) {
  return std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/robot_" + name + ".yaml";
}
std::string job(const std::string& name) {
  return std::string(ROBODAMP_SOURCE_DIR) + "/config/commissioning/job_" + name + ".yaml";
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("robodamp_commission_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

commission::CommissionSettings settings(const std::string& robot, const fs::path& dir) {
  commission::CommissionSettings s;
  s.config_path = cell(robot);
  s.job_path = job(robot);
  s.out_dir = dir.string();
  s.command_line = "test";
  return s;
}

std::vector<std::string> lines;
const auto collect = [](const std::string& l) { lines.push_back(l); };

// The rows of a plot's data file: numbers per column ("NaN" kept as NaN).
std::vector<std::vector<double>> rows_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<double>> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::vector<double> r;
    std::string w;
    while (ss >> w) r.push_back(w == "NaN" ? NAN : std::stod(w));
    if (!r.empty()) out.push_back(r);
  }
  return out;
}

TEST(Commission, ATwoModeRobotNoPresetDescribesIsCommissionedAndVerifiedOnTheCell) {
  const fs::path dir = fresh_dir("a");
  commission::CommissionSettings s = settings("a_two_modes", dir);
  s.tune.global_evaluations = 40;  // a short search: the test is the chain, not the optimum
  s.tune.local_evaluations = 20;
  const commission::CommissionResult r = commission::commission(s, collect);
  ASSERT_EQ(r.outcome, commission::Outcome::kVerified) << commission::to_string(r.stage) << ": " << r.reason;
  // Identified within 1 % of the robot's true modes (5.5 and 16 Hz) and its actuator's delay (0.45 ms).
  ASSERT_TRUE(r.identified);
  ASSERT_EQ(r.identified->frfs.front().fit.modes.size(), 2u);
  EXPECT_NEAR(r.identified->frfs.front().fit.modes[0].natural_freq_hz, 5.5, 0.055);
  EXPECT_NEAR(r.identified->frfs.front().fit.modes[1].natural_freq_hz, 16.0, 0.16);
  // Verified on the cell: every FRF's improvement within 5 points of its prediction, and the damped cut in
  // time on the cell at least the promise less 5 % at the lobes' minimum and the job's speed.
  ASSERT_TRUE(r.cell && r.promise);
  for (const auto& f : r.cell->frfs) {
    EXPECT_NEAR(f.measured_improvement_pct, f.predicted_improvement_pct, 5.0) << f.name;
    EXPECT_GT(f.predicted_improvement_pct, 3.0) << f.name;  // a short search (the full one reaches ~17 %)
  }
  EXPECT_GE(r.cell->time_domain_at_min_mm, 0.95 * r.promise->min_depth_mm);
  EXPECT_GE(r.cell->time_domain_at_speed_mm, 0.95 * r.promise->depth_at_speed_mm);
  EXPECT_GT(r.promise->min_depth_mm, r.promise->open_min_depth_mm);
  // The written configuration reads back with the tuned controller and says what verified it.
  const config::Config written = config::load_config_file((dir / "configuration.yaml").string());
  EXPECT_EQ(written.controller.gain_ns_per_m, r.tuned_config->controller.gain_ns_per_m);
  const std::string text = test::read_file((dir / "configuration.yaml").string());
  EXPECT_NE(text.find("Verified on the simulated plant in process: the damped cut in time"), std::string::npos) << text;
  // With its speed schedule over the job's range: never worse than the open loop at the speeds checked, checked
  // in time at 0.95 x its limit where it damps, and written with its promises.
  ASSERT_TRUE(r.schedule);
  EXPECT_EQ(r.schedule->summary.scheduled_worse_share, 0.0);
  EXPECT_GE(r.schedule->summary.scheduled_min_mm, r.schedule->summary.open_min_mm);
  EXPECT_GE(r.schedule->summary.scheduled_mean_ratio, r.schedule->summary.fixed_mean_ratio);
  ASSERT_TRUE(r.schedule_in_time);
  EXPECT_TRUE(r.schedule_in_time->all_stable());
  EXPECT_TRUE(r.schedule_in_time->switches_within_limits());
  ASSERT_TRUE(written.controller.speed_schedule);
  EXPECT_EQ(written.controller.speed_schedule->bands.size(), r.schedule->bands.size());
  EXPECT_NE(text.find("# The speed schedule (controller.speed_schedule) was verified"), std::string::npos) << text;
  // Every file commission writes is valid input again, as written and in block and flow style: a tune of it
  // (the next commissioning) writes a file that reads back.
  for (const char* file : {"identified.yaml", "tuned.yaml", "configuration.yaml"}) {
    const std::string original = test::read_file((dir / file).string());
    for (const std::string& t : {original, test::in_style(original, YAML::EmitterStyle::Block),
                                 test::in_style(original, YAML::EmitterStyle::Flow)}) {
      const config::Config c = config::parse_config(t, (dir / file).string());
      const config::EditedYaml again = tune::tuned_config_text(c, r.tuned->candidate);
      EXPECT_EQ(config::parse_config(again.text, (dir / file).string()).controller.gain_ns_per_m,
                r.tuned->candidate.gain_ns_per_m)
          << file;
    }
  }
  // What a modal package opens (issue 48): every FRF measured with its coherence and the identified modes.
  {
    const measfiles::UffFile measured =
        measfiles::read_uff((dir / "measurement" / identify::kMeasurementUffName).string());
    EXPECT_EQ(measured.functions.size(), 2u * (r.identified->frfs.size() + 1));
    const measfiles::UffFile modes = measfiles::read_uff((dir / identify::kModesUffName).string());
    EXPECT_EQ(modes.modes.size(), 2u);
  }
  // The report: self-contained (every plot inlined), verified, and its plotted data are the computed series.
  const std::string html = test::read_file(r.report_path);
  EXPECT_NE(html.find("VERIFIED"), std::string::npos);
  // It opens with what the damper does for the job (before the stages), in words and one picture, and says
  // when, with what and for whom.
  const auto opens = html.find("<h2>What the damper does for this job</h2>"), stages = html.find("<h2>1. Stages</h2>");
  ASSERT_NE(opens, std::string::npos);
  EXPECT_LT(opens, stages);
  EXPECT_NE(html.find("the schedule is never worse than no damper"), std::string::npos);
  EXPECT_NE(html.find("configuration SHA-256 <code>"), std::string::npos);
  EXPECT_NE(html.find("operator "), std::string::npos);
  // How far the modes may move is measured and said (a warning under +-5 %), matching the loop model.
  ASSERT_TRUE(r.robustness);
  char held[96];
  std::snprintf(held, sizeof held, "damps the modes it damps from %.1f %% to +%.1f %% of mode shift",
                -r.robustness->down.pct, r.robustness->up.pct);
  EXPECT_NE(html.find(held), std::string::npos) << held;
  EXPECT_EQ(html.find("<b>WARNING:</b> Measured on the identified plant") != std::string::npos,
            r.robustness->pct() < tune::kRobustShiftWarnPct);
  for (const auto* l : {&r.robustness->down, &r.robustness->up}) {
    if (!l->reached_max) {
      EXPECT_TRUE(l->reason.find("the loop unstable") != std::string::npos ||
                  l->reason.find("not damped") != std::string::npos)
          << l->reason;
    }
  }
  const auto sched_rows = rows_of(dir / "plots" / "schedule_lobes.dat");
  ASSERT_EQ(sched_rows.size(), r.schedule->speeds.size());
  for (std::size_t i = 0; i < sched_rows.size(); ++i) {
    EXPECT_NEAR(sched_rows[i][0], r.schedule->speeds[i].rpm, 1e-8 * r.schedule->speeds[i].rpm);  // written to 10 digits
    EXPECT_NEAR(sched_rows[i][3], r.schedule->speeds[i].scheduled_mm, 1e-8 * r.schedule->speeds[i].scheduled_mm);
    EXPECT_GE(sched_rows[i][3], 0.995 * sched_rows[i][1])
        << "the plotted schedule below the plotted open loop at " << sched_rows[i][0];
    const auto& cap = r.schedule->bands.at(r.schedule->speeds[i].band).depth_limit_mm;
    EXPECT_DOUBLE_EQ(sched_rows[i][4], cap ? *cap : -1.0) << "the band's depth limit at " << sched_rows[i][0];
    if (cap) {
      EXPECT_LE(sched_rows[i][3], *cap + 1e-9) << "the schedule at most its band's depth limit at " << sched_rows[i][0];
    }
  }
  std::size_t images = 0;
  for (std::size_t p = html.find("data:image/png;base64,"); p != std::string::npos;
       p = html.find("data:image/png;base64,", p + 1))
    ++images;
  EXPECT_EQ(images, 3u * 3u + 3u);  // per FRF: fit, stabilisation, cell; the actuator; the lobes; the schedule
  const auto& f0 = r.identified->frfs.front();
  // The FRF figure's first block (plot/frf_figure.hpp: f, |measured|, |fitted|, coherence; the phases follow
  // in blocks of two columns): the fitted band alone, the fit drawn over all of it.
  std::vector<std::vector<double>> fit_rows;
  for (auto& row : rows_of(dir / "plots" / (f0.name + "_fit.dat")))
    if (row.size() == 4) fit_rows.push_back(std::move(row));
  const auto in_band = static_cast<std::size_t>(std::count_if(f0.data.f_hz.begin(), f0.data.f_hz.end(), [&](double f) {
    return f > 0.0 && f >= f0.fit.band_lo_hz && f <= f0.fit.band_hi_hz;
  }));
  ASSERT_EQ(fit_rows.size(), in_band);
  for (const auto& row : fit_rows) {
    const double expected = std::abs(identify::fitted_receptance(f0.fit, row[0]));
    ASSERT_TRUE(std::isfinite(row[2])) << row[0] << " Hz: the fit is drawn over the whole band";
    ASSERT_NEAR(row[2], expected, 1e-4 * expected) << row[0] << " Hz";
    ASSERT_GE(row[3], 0.0) << row[0] << " Hz: the coherence beside";
  }
  EXPECT_GT(in_band, 1000u);
  // The actuator's fitted curve is drawn through the same sampled loop as the measured one: their phases
  // agree above 20 Hz (Eq. 3 alone left out the hold and the tick of computation: 10-20 deg at 100 Hz).
  const auto act_rows = rows_of(dir / "plots" / "actuator_fit.dat");
  ASSERT_EQ(act_rows.size(), r.identified->actuator.f_hz.size());
  double worst_deg = 0.0;
  for (const auto& row : act_rows)
    if (row[0] > 20.0) worst_deg = std::max(worst_deg, std::abs(std::remainder(row[4] - row[2], 360.0)));
  EXPECT_LT(worst_deg, 3.0);
  const auto lobe_rows = rows_of(dir / "plots" / "lobes.dat");
  EXPECT_GT(lobe_rows.size(), r.promise->damped_curve_mm.size());
  fs::remove_all(dir);
}

TEST(Commission, BadMeasurementsStopAtTheirStageWithTheReasonAndWriteNoConfiguration) {
  const fs::path dir = fresh_dir("bad");
  const commission::MeasureOutcome m = commission::measure(cell("a_two_modes"), (dir / "measurement").string());
  ASSERT_EQ(m.status, commission::MeasureStatus::kOk) << m.message;
  std::ofstream(dir / "configuration.yaml") << "# left from an earlier run\n";
  commission::CommissionSettings s = settings("a_two_modes", dir);
  s.from = commission::Stage::kIdentify;
  const fs::path frf = dir / "measurement" / "frf_1_1.csv";
  const std::string good = test::read_file(frf.string());

  // NaN in an FRF.
  {
    std::string bad = good;
    const auto line = bad.find('\n', bad.find('\n', bad.find('\n') + 1) + 1);
    const auto comma = bad.find(',', line + 1);
    bad.replace(line + 1, comma - line - 1, "nan");
    std::ofstream(frf) << bad;
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
    EXPECT_EQ(r.stage, commission::Stage::kIdentify);
    EXPECT_NE(r.reason.find("frf_1_1.csv"), std::string::npos) << r.reason;
    EXPECT_FALSE(fs::exists(dir / "configuration.yaml"));
    EXPECT_NE(test::read_file(r.report_path).find("NOT VERIFIED"), std::string::npos);
  }
  // No coherence: every bin below the fit's threshold.
  {
    std::istringstream in(good);
    std::ostringstream out;
    std::string line;
    bool header = true;
    while (std::getline(in, line)) {
      if (header || line.empty() || line[0] == '#') {
        out << line << '\n';
        header = header && (line.empty() || line[0] == '#' || line.find("freq") != std::string::npos);
        continue;
      }
      out << line.substr(0, line.rfind(',')) << ",0.05\n";
    }
    std::ofstream(frf) << out.str();
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput) << r.reason;
    EXPECT_EQ(r.stage, commission::Stage::kIdentify);
    EXPECT_NE(r.reason.find("coheren"), std::string::npos) << r.reason;
    EXPECT_FALSE(fs::exists(dir / "configuration.yaml"));
  }
  std::ofstream(frf) << good;
  // A chirp that saturated the actuator (as the measurement's own record says).
  {
    const fs::path man = dir / "measurement" / "measurement.json";
    const std::string j = test::read_file(man.string());
    std::string bad = j;
    const auto p = bad.find("\"saturated_ticks\": 0");
    ASSERT_NE(p, std::string::npos);
    bad.replace(p, 20, "\"saturated_ticks\": 250");
    std::ofstream(man) << bad;
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
    EXPECT_EQ(r.stage, commission::Stage::kIdentify);
    EXPECT_NE(r.reason.find("saturated"), std::string::npos) << r.reason;
    std::ofstream(man) << j;
  }
  // Resuming from a stage whose input is missing.
  {
    s.from = commission::Stage::kVerify;
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
    EXPECT_EQ(r.stage, commission::Stage::kTune);
    EXPECT_NE(r.reason.find("tuned.yaml"), std::string::npos) << r.reason;
  }
  // A tuned configuration whose loop is unstable on the identified model (K far above its limit).
  {
    const std::string identified = test::read_file((dir / "identified.yaml").string());
    std::ofstream(dir / "tuned.yaml")
        << config::edit_yaml(identified, {{{"controller", "gain_ns_per_m"}, YAML::Node("90000")}}).text;
    s.from = commission::Stage::kVerify;
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
    EXPECT_EQ(r.stage, commission::Stage::kTune);
    EXPECT_NE(r.reason.find("unstable on the identified model (K = 90000 N s/m"), std::string::npos) << r.reason;
    EXPECT_FALSE(fs::exists(dir / "configuration.yaml"));
    fs::remove(dir / "tuned.yaml");
  }
  // A missing job file.
  {
    s.from = commission::Stage::kMeasure;
    s.job_path = (dir / "no_such_job.yaml").string();
    const auto r = commission::commission(s, collect);
    EXPECT_EQ(r.outcome, commission::Outcome::kBadInput);
    EXPECT_NE(r.reason.find("no_such_job.yaml"), std::string::npos) << r.reason;
    EXPECT_FALSE(fs::exists(dir / "configuration.yaml"));
  }
  EXPECT_THROW((void)commission::stage_from_string("write"), std::invalid_argument);
  fs::remove_all(dir);
}

// The command a written configuration's header gives to commission again: what was given, the defaults left out
// (on the cell), every choice spelled out (along the path, whose budgets are its own).
TEST(Commission, TheCommandLineInTheWrittenFilesIsTheOneThatWasGiven) {
  commission::CommissionSettings s;
  s.config_path = "cell.yaml", s.job_path = "job.yaml", s.out_dir = "out";
  EXPECT_EQ(commission::command_line(s), "robodamp commission --config cell.yaml --job job.yaml --out out");
  s.shift_pct = 2.5, s.tune.global_evaluations += 1, s.tune.seed = 7, s.schedule_gains += 2;
  s.tap_tests = {"a.unv", "b.unv"};
  EXPECT_EQ(commission::command_line(s),
            "robodamp commission --config cell.yaml --job job.yaml --out out --shift-pct 2.5 --evaluations " +
                std::to_string(s.tune.global_evaluations) + " --seed 7 --schedule-gains " +
                std::to_string(s.schedule_gains) + " --tap-tests a.unv --tap-tests b.unv");
  commission::PathCommissionSettings p;
  p.config_path = "cell.yaml", p.job_path = "job.yaml", p.out_dir = "out", p.dwells = 2;
  p.trajectory = {"0:-100,10,90", "20:-100,10,90"}, p.hold_out = {"dwell_2"};
  p.pose_tune.tune.global_evaluations = 60, p.pose_tune.tune.local_evaluations = 30, p.pose_tune.tune.seed = 3;
  p.pose_tune.max_regions = 2, p.map_points = 5;
  EXPECT_EQ(commission::command_line(p),
            "robodamp commission --config cell.yaml --job job.yaml --out out --along-path --dwells 2 --pose-at "
            "0:-100,10,90 --pose-at 20:-100,10,90 --hold-out dwell_2 --evaluations 60 --polish 30 --map-points 5 "
            "--max-regions 2 --seed 3");
}

TEST(Commission, TheRobustShiftFollowsTheFitsSpreadWithinItsBounds) {
  identify::CommissioningResult r;
  identify::IdentifiedFrf a, b;
  a.fit.modes = {{10.0, 0.02, 0, 0, 0}, {20.0, 0.02, 0, 0, 0}};
  b.fit.modes = {{10.05, 0.02, 0, 0, 0}, {20.0, 0.02, 0, 0, 0}};
  r.frfs = {a, b};
  const auto [pct, why] = commission::modal_uncertainty_pct(r, 1.0, 10.0);
  EXPECT_NEAR(pct, 1.5, 1e-9);  // 3 x the 0.5 % spread of the 10 Hz mode
  EXPECT_NE(why.find("10.000 Hz"), std::string::npos) << why;
  r.frfs[1].fit.modes[0].natural_freq_hz = 10.0;
  EXPECT_NEAR(commission::modal_uncertainty_pct(r, 1.0, 10.0).first, 1.0, 1e-9);  // the floor
  // A close pair (10.0 and 10.2 Hz, in both FRFs): each mode is compared with its own, not with the other.
  r.frfs[0].fit.modes = {{10.0, 0.02, 0, 0, 0}, {10.2, 0.02, 0, 0, 0}};
  r.frfs[1].fit.modes = {{10.01, 0.02, 0, 0, 0}, {10.2, 0.02, 0, 0, 0}};
  EXPECT_NEAR(commission::modal_uncertainty_pct(r, 0.1, 10.0).first, 0.3, 1e-9);
}

// Robot A's compensator as `robodamp commission` tuned it (K 849 N s/m): feasible on the robot and on its modes
// 1.3 x higher, where the constraints-only plant leaves the objective to the full one; infeasible with the modes
// 0.8 x lower, where the shifted plant binds (the worst case is its violation).
TEST(Tune, AConstraintsOnlyPlantBindsItsConstraintsAndLeavesTheObjectiveToTheFullPlant) {
  const config::Config base = config::load_config_file(cell("a_two_modes"));
  const config::MillingConfig j = config::load_milling_config(job("a_two_modes"));
  tune::TuneSettings s;
  const tune::Evaluator full(base, j, s, "nominal");
  tune::Candidate c;
  c.gain_ns_per_m = 849.474;
  c.fz_hz = 35.9708, c.zeta_z = 0.217842, c.fp_hz = 17.1254, c.zeta_p = 0.879308, c.fa_hz = 29.4757, c.fb_hz = 3.76324;
  c.polarity = 1;
  const tune::Evaluation alone = full(c);
  ASSERT_TRUE(alone.feasible()) << alone.violation;
  for (const double shift : {1.3, 0.8}) {
    tune::Evaluator shifted(tune::with_shifted_modes(base, shift), std::nullopt, s, "shifted");
    shifted.set_constraints_only(true);
    const tune::Evaluation both = tune::evaluate_worst({&full, &shifted}, c);
    const tune::Evaluation sh = shifted(c);
    EXPECT_EQ(sh.min_depth_mm, 0.0) << shift << ": no lobes computed";
    if (shift > 1.0) {
      ASSERT_TRUE(sh.feasible()) << sh.violation;
      EXPECT_EQ(both.objective, alone.objective);
      EXPECT_EQ(both.accurate_min_mm, alone.accurate_min_mm);
      EXPECT_TRUE(both.feasible());
    } else {
      ASSERT_GT(sh.violation, alone.violation) << "the modes 0.8 x lower bind";
      EXPECT_EQ(both.plant, "shifted");
      EXPECT_EQ(both.violation, sh.violation);
      EXPECT_FALSE(both.feasible());
    }
    EXPECT_LE(both.gain_margin_db, std::min(alone.gain_margin_db, sh.gain_margin_db));
  }
}

// The controller `robodamp commission` tuned for the default preset's cell (K 826 N s/m, polarity -1, a
// compensator with a pole near 0.1 Hz): on the quiet cell its command beats up and down well below the
// instability detector's floor. A hammer blow at the end of such a rise once completed a run of growing
// blocks and tripped "instability" on a stable loop with 11 dB of gain margin; a run now counts only from
// within one growth factor of the floor. The impact tests on the cell hold, and their improvements match
// the prediction.
TEST(Commission, AHitAtTheEndOfARisingQuietEnvelopeIsNotAnInstability) {
  const config::Config cell = config::load_config_file(test::preset("horizontal_c2"));
  const std::string entry =
      "{kind: compensator, model: rational, numerator: [0.002478155713971838, 0.32919256175699446, 24.968220864842035, "
      "1065.806967171825], denominator: [0.001572512595165921, 0.28183609945532384, 1.5424148350174098, 1]}";
  const config::EditedYaml text =
      config::edit_yaml(cell.yaml_text, {{{"controller", "gain_ns_per_m"}, YAML::Node("825.8137")},
                                         {{"controller", "polarity"}, YAML::Node("-1")},
                                         {{"controller", "match_freq_hz"}, YAML::Node("9.20158")},
                                         {{"controller", "chain", std::size_t{5}}, YAML::Load(entry)}});
  const config::Config tuned = config::parse_config(text.text, "commissioned");
  ASSERT_EQ(tuned.controller.chain[5].denominator.size(), 4u);
  const config::MillingConfig j =
      config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml");
  tune::Verification promise;  // the depths are not what this checks
  promise.min_rpm = 423.7, promise.speed_rpm = 699.3, promise.min_depth_mm = 1.0, promise.depth_at_speed_mm = 1.3;
  const commission::CellCheck c = commission::check_on_cell(cell, tuned, j, promise);
  EXPECT_EQ(c.closed_trip, "none");
  EXPECT_EQ(c.closed_active_share, 1.0);
  ASSERT_EQ(c.frfs.size(), 3u);
  for (const auto& f : c.frfs) {
    EXPECT_NEAR(f.measured_improvement_pct, f.predicted_improvement_pct, 5.0) << f.name;
    EXPECT_GT(f.measured_improvement_pct, 150.0) << f.name;
  }
}

}  // namespace
}  // namespace robodamp
