// `robodamp chatter --signal FILE`: a recorded cut's vibration or sound (a table, a WAV, a universal file's
// time history, a robodamp recording) -> chatter over time, its frequency, and the speeds to try next
// (milling/chatter_listen.hpp). docs/milling.md, "Listening to a recorded cut".
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "identify/recorded_signal.hpp"
#include "milling/chatter_listen.hpp"
#include "milling/listen_report.hpp"

namespace robodamp::apps {

namespace {

struct ChatterArgs {
  std::string signal, column, rpm_column, response, plot_dir;
  std::optional<double> rate_hz, rpm, floor, full_scale_mps2;
  int channel{1}, teeth{0};
  std::optional<int> record;
  std::vector<double> rpm_range;  // empty: 100 .. 30000, or the job's
  // The speeds checked by the accurate method: the cell's configuration, its job (default spindle.job),
  // the recorded depth (default the job's) and whether the damper ran.
  std::string config_path, job_path;
  std::optional<double> depth_mm;
  bool damped{false};
  double window_s{4.0}, max_hz{1000.0};
  JsonOut json;
};

int run_chatter(const ChatterArgs& a) {
  milling::ListenReport r;
  std::vector<double> range;
  std::optional<milling::SpeedAdvice> advice;
  std::string described;
  try {
    if (a.teeth == 0) throw std::invalid_argument("--teeth: the cutter's teeth are required (the tooth-passing lines)");
    range = a.rpm_range.empty() ? std::vector<double>{100.0, 30000.0} : a.rpm_range;
    if (range.size() != 2 || !(range[1] > range[0])) throw std::invalid_argument("--rpm-range: two speeds, LO < HI");
    const std::optional<milling::ListenCell> cell =
        milling::listen_cell(a.config_path, a.job_path, a.depth_mm.has_value() || a.damped, a.teeth);
    if (cell && a.rpm_range.empty())
      range = {cell->job.lobes.rpm_min, std::min(cell->job.lobes.rpm_max, cell->cfg.spindle.rpm_max)};
    identify::SignalOptions o;
    o.column = a.column, o.rpm_column = a.rpm_column, o.rate_hz = a.rate_hz, o.channel = a.channel,
    o.full_scale_mps2 = a.full_scale_mps2, o.record = a.record;
    if (!a.response.empty()) o.response = identify::parse_dof(a.response);
    const milling::RecordedSignal sig = identify::read_recorded_signal(a.signal, o, described);
    milling::ListenSettings s;
    s.teeth = a.teeth, s.rpm = a.rpm, s.rpm_min = range[0], s.rpm_max = range[1];
    s.window_s = a.window_s, s.max_hz = a.max_hz, s.floor = a.floor;
    r = milling::listen(sig, s);
    if (cell && r.chatter_hz > 0.0)
      advice = milling::checked_speeds(*cell, r, a.depth_mm, a.damped, range[0], range[1]);
  } catch (const std::exception& e) {
    std::cerr << "robodamp chatter: " << e.what() << '\n';
    return 2;
  }
  const std::string t = milling::listen_text(r, a.teeth, a.signal + " (" + described + ")", advice, a.damped);
  const nlohmann::json j = milling::listen_json(r, a.teeth, advice, a.damped);
  return print_report(
      j.dump(2), a.json, "chatter", t, a.plot_dir, [&] { return milling::plot_listen(r, a.plot_dir); },
      "plots in " + a.plot_dir);
}

}  // namespace

void register_chatter(Registry& r) {
  auto a = std::make_shared<ChatterArgs>();
  CLI::App* sub =
      r.add("chatter",
            "Listen to a recorded cut: chatter over time, its frequency and the speeds to try (a table, WAV, "
            "universal file or robodamp recording)",
            [a] { return run_chatter(*a); });
  sub->add_option("--signal", a->signal,
                  "The recording: a table (time column or --rate-hz), a WAV, a universal file's time history, a "
                  "robodamp recording")
      ->required()
      ->check(CLI::ExistingFile);
  r.whole_number(sub, "--teeth", a->teeth, {"(teeth)", 1, 32}, "The cutter's teeth");
  r.number(sub, "--rpm", a->rpm, {"rpm", 0.0, 200000.0, false, false},
           "The spindle speed (default: estimated from the signal's harmonics)");
  r.numbers(sub, "--rpm-range", a->rpm_range, {"rpm", 1.0, 200000.0},
            "Where the estimate searches and the speeds to try lie: LO HI (default 100 30000)");
  sub->add_option("--rpm-column", a->rpm_column,
                  "A table's spindle-speed column (rpm), name or number: each window judged at its own speed");
  sub->add_option("--column", a->column, "A table's column: its name or number (default: the first that is not time)");
  r.number(sub, "--rate-hz", a->rate_hz, {"Hz", 0.0, 1e7, false, false},
           "A table's sample rate when it has no time column");
  r.whole_number(sub, "--channel", a->channel, {"(channel)", 1, 64}, "A sound file's channel (default 1)");
  r.number(sub, "--full-scale-mps2", a->full_scale_mps2, {"m/s^2", 0.0, 1e6, false, false},
           "A sound file's acceleration at full scale (an accelerometer recorded as sound)");
  r.whole_number(sub, "--record", a->record, {"(record)", 1, 1000000}, "A universal file's function record");
  sub->add_option("--response", a->response, "A universal file's record by its response DOF NODE:DIR");
  r.number(sub, "--window-s", a->window_s, {"s", 0.2, 60.0},
           "One verdict per window of this length (default 4, the cell's live indicator's span)");
  r.number(sub, "--max-hz", a->max_hz, {"Hz", 10.0, 1e5},
           "The band analysed (default 1000: a robot's modes and their tooth-passing lines)");
  r.number(sub, "--floor", a->floor, {"(the signal's unit)", 0.0, 1e9},
           "Non-harmonic RMS below this is not chatter (default 0.05 m/s^2 for an acceleration)");
  sub->add_option("--config", a->config_path,
                  "The cell's configuration: the speeds to try are checked by the accurate method on its job")
      ->check(CLI::ExistingFile);
  sub->add_option("--job", a->job_path, "The milling job (default the configuration's spindle.job)")
      ->check(CLI::ExistingFile);
  r.number(sub, "--depth-mm", a->depth_mm, {"mm", 0.0, 100.0, false, false},
           "The recorded cut's axial depth (default the job's)");
  sub->add_flag("--damped", a->damped, "The recording was made with the damper on: the damped limits apply");
  r.json(sub, a->json,
         "Per window: start_s, end_s, verdict, chatter_hz, chatter_share; onset_s, end_s, chatter_hz, rpm, rpm_source, "
         "rate_hz, samples");
  r.plot_dir(sub, a->plot_dir, "chatter_spectrogram.png and chatter_verdict.png");
}

}  // namespace robodamp::apps
