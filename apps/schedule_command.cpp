// `robodamp schedule`: the controller and K by spindle speed (tune/speed_schedule.hpp, docs/tuning.md): for a
// cell and its milling job, the deepest damped limit at every speed, K = 0 included, so that the damper is
// never worse than none; the verdict in the machinist's terms; --out writes the cell's configuration with its
// controller.speed_schedule, checked by the configuration's own rules and the cell's analysis before writing.
#include <fstream>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "plot/gnuplot.hpp"
#include "tune/speed_schedule.hpp"
#include "tune/speed_schedule_report.hpp"
#include "tune/speed_schedule_file.hpp"

namespace robodamp::apps {

namespace {

struct ScheduleArgs : tune::ScheduleCommand {
  ScheduleArgs() { config_path = default_cell_config(); }
  JsonOut json;
  std::string plot_dir;
};

// The cell's text with the schedule, moved to --out (its relative paths rebased), checked before it is written.
int write_config(const ScheduleArgs& a, config::Config cell, const tune::SpeedSchedule& s) {
  bool comments_kept = true;
  const std::string text = tune::scheduled_file_text(a, std::move(cell), s, comments_kept);  // checked: throws (exit 2)
  if (!comments_kept)
    std::fprintf(stderr,
                 "schedule: %s could not be edited in place; written again from its data, without its comments\n",
                 a.config_path.c_str());
  std::ofstream out(a.out_path);
  out << text;
  if (!out.good()) {
    std::cerr << "robodamp schedule: cannot write " << a.out_path << '\n';
    return 1;
  }
  std::printf("wrote %s\n", a.out_path.c_str());
  return 0;
}

// 0 scheduled (and written), 3 the schedule is worse than the open loop somewhere (nothing written), 2 bad input.
int run_schedule(const ScheduleArgs& a) {
  const config::Config cell = config::load_config_file(a.config_path);
  const std::string job_path = !a.job_path.empty() ? a.job_path : cell.spindle.job_resolved;
  if (job_path.empty())
    throw config::ConfigError(
        {{a.config_path,
          {},
          "--job",
          "missing: give the milling job (config/milling/*.yaml) or set spindle.job in the configuration"}});
  const config::MillingConfig job = config::load_milling_config(job_path);
  const config::StructureConfig* structure = job.find_structure(job.structure);
  if (structure == nullptr) throw config::ConfigError({{job_path, {}, "structure", "names no structure of the job"}});
  tune::ScheduleSettings s = a.settings;
  s.progress = [last = std::string()](const std::string& what, std::size_t done, std::size_t of) mutable {
    if (what != last || done == of || done % 50 == 0)
      std::cerr << "[schedule] " << what << ": " << done << "/" << of << '\n';
    last = what;
  };
  std::vector<tune::NamedController> others;
  for (const auto& f : a.controllers) others.push_back(tune::controller_of_file(f));
  const tune::SpeedSchedule sched = tune::schedule_speeds(cell, others, job, *structure, s);
  const std::string text = tune::schedule_text(sched, a.config_path, job_path);
  const std::string plot = plot_file(a.plot_dir, "", "schedule_lobes.png");
  const int printed = print_report(
      tune::schedule_json(sched).dump(2), a.json, "schedule", text, plot,
      [&] {
        const auto [data, script] = tune::schedule_plot(sched, "Limiting depth by spindle speed: " + job_path);
        return plot::run_gnuplot(script, data, plot);
      },
      plot);
  if (printed != 0) return printed;
  if (sched.summary.scheduled_worse_share > 0.0) {
    std::cerr
        << "robodamp schedule: the schedule is worse than the open loop at some speeds (above): nothing written\n";
    return 3;
  }
  return a.out_path.empty() ? 0 : write_config(a, cell, sched);
}

}  // namespace

void register_schedule(Registry& r) {
  auto a = std::make_shared<ScheduleArgs>();
  CLI::App* sub =
      r.add("schedule",
            "The controller and K by spindle speed: the deepest damped limit at every speed of the job (K = 0 "
            "included), so the damper is never worse than none; --out writes controller.speed_schedule",
            [a] { return run_schedule(*a); });
  sub->add_option("--config", a->config_path, "The cell's configuration (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--job", a->job_path, "Milling job (config/milling/*.yaml); default the configuration's spindle.job")
      ->check(CLI::ExistingFile);
  sub->add_option("--controller", a->controllers,
                  "Another configuration whose controller (chain, polarity) a band may run, with the cell's robot "
                  "(repeat for more)")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_path, "Write the configuration with its speed schedule here (only when never worse)");
  r.json(sub, a->json, "Every speed's depths (open, as configured, scheduled), the bands and the verdict");
  r.plot_dir(sub, a->plot_dir,
             "schedule_lobes.png: the open loop, the configured controller and the schedule by speed,");
  r.whole_number(
      sub, "--speeds", a->settings.speeds, {"(speeds)", 2, 5000},
      "Grid speeds over the job's lobes range (default its time_domain.sdm_points); checks are added between");
  r.whole_number(sub, "--gains", a->settings.gains_per_controller, {"(gains per controller)", 1, 24},
                 "Gains tried per controller, log-spaced up to the largest that keeps the margins");
  r.number(sub, "--gain-margin-db", a->settings.gain_margin_min_db, {"dB", 0.0, 40.0},
           "Smallest gain margin of any gain used");
  r.number(sub, "--phase-margin-deg", a->settings.phase_margin_min_deg, {"deg", 0.0, 90.0},
           "Smallest phase margin of any gain used");
  r.number(sub, "--delay-margin-ms", a->settings.delay_margin_min_ms, {"ms", 0.0, 1000.0},
           "Smallest delay margin of any gain used");
}

}  // namespace robodamp::apps
