// `robodamp chatter --signal FILE`: a recorded cut's vibration or sound (a table, a WAV, a universal file's
// time history, a robodamp recording) -> chatter over time, its frequency, and the speeds to try next
// (milling/chatter_listen.hpp). docs/milling.md, "Listening to a recorded cut".
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/cli.hpp"
#include "apps/gnuplot.hpp"
#include "identify/recorded_signal.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/chatter.hpp"
#include "milling/chatter_listen.hpp"
#include "milling/live_stability.hpp"
#include "milling/speed_advice.hpp"

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

// Each speed to try checked as the cell's advisor checks it: the accurate limit at the recorded depth there.
struct Cell {
  config::Config cfg;
  config::MillingConfig job;
};

std::optional<Cell> cell_of(const ChatterArgs& a) {
  if (a.config_path.empty()) {
    if (!a.job_path.empty() || a.depth_mm || a.damped)
      throw std::invalid_argument("--job, --depth-mm and --damped need --config (the cell)");
    return std::nullopt;
  }
  config::Config cfg = config::load_config_file(a.config_path);
  const std::string job_path = !a.job_path.empty() ? a.job_path : cfg.spindle.job_resolved;
  if (job_path.empty()) throw std::invalid_argument(a.config_path + ": no spindle.job: give --job");
  Cell c{std::move(cfg), config::load_milling_config(job_path)};
  if (c.job.tool.teeth != a.teeth)
    throw std::invalid_argument("--teeth " + std::to_string(a.teeth) + " but the job " + job_path +
                                " cuts with tool.teeth = " + std::to_string(c.job.tool.teeth));
  return c;
}

milling::SpeedAdvice checked_speeds(const ChatterArgs& a, const Cell& c, const milling::ListenReport& r,
                                    const std::vector<double>& range) {
  const config::Config& cfg = c.cfg;
  config::MillingConfig job = c.job;
  milling::SpeedAdviceRequest q;
  q.rpm = r.rpm, q.depth_mm = a.depth_mm.value_or(job.cut.axial_mm), q.set = 0,
  q.gain_ns_per_m = cfg.controller.gain_ns_per_m;
  q.damped = a.damped, q.chatter_hz = r.chatter_hz, q.trigger = "chatter";
  milling::LiveStability stability(std::move(job), cfg.spindle.structure, {cfg});
  return milling::advise_speed(stability, q, range[0], range[1]);
}

nlohmann::json to_json(const milling::ListenReport& r, int teeth) {
  const double tooth_hz = r.rpm * teeth / 60.0;  // the chatter's family: milling/chatter.hpp
  nlohmann::json w = nlohmann::json::array();
  for (const auto& x : r.windows)
    w.push_back({{"start_s", x.start_s},
                 {"end_s", x.end_s},
                 {"verdict", milling::to_string(x.verdict)},
                 {"chatter_hz", x.chatter_hz},
                 {"chatter_family_hz", milling::chatter_family_hz(x.chatter_hz, tooth_hz)},
                 {"chatter_share", x.chatter_share},
                 {"rms", x.rms},
                 {"once_per_rev_ratio", x.indicator.once_per_rev_ratio},
                 {"rpm", x.rpm}});
  nlohmann::json speeds = nlohmann::json::array();
  for (const auto& s : r.speeds) speeds.push_back({{"rpm", s.rpm}, {"lobe", s.lobe}});
  nlohmann::json j = {{"windows", w},
                      {"chatter_hz", r.chatter_hz},
                      {"chatter_family_hz", milling::chatter_family_hz(r.chatter_hz, tooth_hz)},
                      {"tooth_hz", tooth_hz},
                      {"rpm", r.rpm},
                      {"rpm_source", r.rpm_source},
                      {"rate_hz", r.rate_hz},
                      {"analysed_rate_hz", r.analysed_rate_hz},
                      {"samples", r.samples},
                      {"warnings", r.warnings},
                      {"speeds_to_try", speeds}};
  j["onset_s"] = r.onset_s ? nlohmann::json(*r.onset_s) : nlohmann::json(nullptr);
  j["end_s"] = r.end_s ? nlohmann::json(*r.end_s) : nlohmann::json(nullptr);
  return j;
}

std::string plots(const milling::ListenReport& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  // pm3d colours each quadrangle by its lower-left corner (corners2color c1): a column, centred on its
  // window, is drawn from half a hop before its centre to half a hop after.
  std::ostringstream sp;
  const double half_hop_s = r.spectrogram_t_s.size() > 1 ? 0.5 * (r.spectrogram_t_s[1] - r.spectrogram_t_s[0]) : 0.0;
  for (std::size_t c = 0; c < r.spectrogram_db.size(); ++c) {
    for (std::size_t k = 0; k < r.spectrogram_hz.size(); ++k)
      sp << plot::num(r.spectrogram_t_s[c] - half_hop_s) << ' ' << plot::num(r.spectrogram_hz[k]) << ' '
         << plot::num(r.spectrogram_db[c][k]) << '\n';
    sp << '\n';
  }
  const double duration_s = r.windows.empty() ? 0.0 : r.windows.back().end_s;
  const double top_hz = r.spectrogram_hz.empty() ? 1.0 : r.spectrogram_hz.back();
  const double bottom_hz = r.spectrogram_hz.empty() ? 0.1 : r.spectrogram_hz.front();
  char title[160];
  if (r.chatter_hz > 0.0)
    std::snprintf(title, sizeof title, "Spectrogram (%.0f rpm, chatter at %.2f Hz)", r.rpm, r.chatter_hz);
  else
    std::snprintf(title, sizeof title, "Spectrogram (%.0f rpm, no chatter)", r.rpm);
  std::ostringstream s;
  s << "set title '" << title << "'\nset xlabel 'time (s)'\nset ylabel 'frequency (Hz)'\nset cblabel 'magnitude (dB)'\n"
    << "set xrange [0:" << plot::num(duration_s) << "]\nset yrange [" << plot::num(bottom_hz) << ":"
    << plot::num(top_hz)
    << "]\nset logscale y\nset view map\nset pm3d map corners2color c1\nset palette defined (0 'black', 1 'purple', 2 "
       "'red', 3 'yellow')\n"
    << "splot DATA u 1:2:3 with pm3d notitle\n";
  if (auto e = run_gnuplot(s.str(), sp.str(), dir + "/chatter_spectrogram.png"); !e.empty()) return e;
  std::ostringstream v;
  for (const auto& w : r.windows) {
    const int level = w.verdict == milling::WindowVerdict::kChatter  ? 2
                      : w.verdict == milling::WindowVerdict::kStable ? 1
                                                                     : 0;
    const double mid_s = 0.5 * (w.start_s + w.end_s);  // where the window's chatter frequency is drawn
    v << plot::num(w.start_s) << ' ' << level << ' ' << plot::num(w.chatter_share) << ' ' << plot::num(w.chatter_hz)
      << ' ' << plot::num(mid_s) << '\n'
      << plot::num(w.end_s) << ' ' << level << ' ' << plot::num(w.chatter_share) << ' ' << plot::num(w.chatter_hz)
      << ' ' << plot::num(mid_s) << '\n';
  }
  std::string onset;
  if (r.onset_s)
    onset = "set arrow from " + plot::num(*r.onset_s) + ", graph 0 to " + plot::num(*r.onset_s) +
            ", graph 1 nohead dt 2 lc rgb 'red'\nset label 'onset " +
            plot::num(std::round(*r.onset_s * 100.0) / 100.0) + " s' at " + plot::num(*r.onset_s) +
            ", graph 0.9 offset 0.5,0 tc rgb 'red'\n";
  const std::string s2 =
      "set multiplot layout 2,1 title 'Chatter over time'\nset grid\nset ylabel 'verdict'\n" + onset +
      "set ytics ('not enough signal' 0, 'stable' 1, 'chatter' 2)\nset yrange [-0.3:2.3]\n"
      "plot DATA u 1:2 w l lw 3 t 'verdict per window'\nset ytics auto\nset yrange [*:*]\nset xlabel 'time (s)'\n"
      "set key bottom right\nset ylabel 'non-harmonic share'\nset yrange [0:1.05]\nset y2label 'chatter frequency "
      "(Hz)'\nset y2tics\nset y2range [0:*]\n"
      "plot DATA u 1:3 w l t 'non-harmonic share of the energy', DATA u 5:($4 > 0 ? $4 : 1/0) axes x1y2 w p pt 7 t "
      "'chatter frequency (per window)'\n"
      "unset multiplot\n";
  return run_gnuplot(s2, v.str(), dir + "/chatter_verdict.png");
}

// The speeds the chatter's advice checked, with their limits and margins (the text after the speeds to try).
std::string checked_text(const milling::SpeedAdvice& advice, bool damped) {
  std::ostringstream t;
  char check[200];
  std::snprintf(check, sizeof check, "Checked by %s at %.3g mm (%s): the limit here is %.3g mm.", advice.method.c_str(),
                advice.depth_mm, damped ? "damped" : "open loop", advice.limit_now_mm);
  t << check;
  if (advice.depth_from_chatter)
    t << " The cut chattered at a speed whose limit is above the depth given, so it was at least that deep (or the "
         "model is "
         "optimistic there): the margins are against the limit.";
  if (!advice.found) t << " No speed qualifies: " << advice.reason << "\n";
  for (const auto& o : advice.options) {
    std::snprintf(check, sizeof check, "\n  %.0f rpm: limit %.3g mm, margin x%.2f (%s)", o.rpm, o.limit_mm, o.margin,
                  o.source.c_str());
    t << check;
  }
  if (advice.found) t << "\n";
  return t.str();
}

// The advice's checked speeds in the JSON ("checked").
nlohmann::json checked_json(const milling::SpeedAdvice& advice, bool damped) {
  nlohmann::json opts = nlohmann::json::array();
  for (const auto& o : advice.options)
    opts.push_back({{"rpm", o.rpm}, {"limit_mm", o.limit_mm}, {"margin", o.margin}, {"source", o.source}});
  return {{"method", advice.method},
          {"depth_mm", advice.depth_mm},
          {"limit_now_mm", advice.limit_now_mm},
          {"found", advice.found},
          {"options", opts},
          {"reason", advice.reason},
          {"damped", damped}};
}

int run_chatter(const ChatterArgs& a) {
  milling::ListenReport r;
  std::vector<double> range;
  std::optional<milling::SpeedAdvice> advice;
  std::string described;
  try {
    if (a.teeth == 0) throw std::invalid_argument("--teeth: the cutter's teeth are required (the tooth-passing lines)");
    range = a.rpm_range.empty() ? std::vector<double>{100.0, 30000.0} : a.rpm_range;
    if (range.size() != 2 || !(range[1] > range[0])) throw std::invalid_argument("--rpm-range: two speeds, LO < HI");
    const std::optional<Cell> cell = cell_of(a);
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
    if (cell && r.chatter_hz > 0.0) advice = checked_speeds(a, *cell, r, range);
  } catch (const std::exception& e) {
    std::cerr << "robodamp chatter: " << e.what() << '\n';
    return 2;
  }
  std::ostringstream t;
  t << "robodamp chatter: " << a.signal << " (" << described << "), " << r.samples << " samples at " << r.rate_hz
    << " Hz, analysed at " << r.analysed_rate_hz << " Hz\n  spindle " << r.rpm << " rpm (" << r.rpm_source << ")\n";
  for (const auto& w : r.warnings) t << "  NOTE: " << w << '\n';
  std::size_t counts[3] = {0, 0, 0};
  for (const auto& w : r.windows) {
    ++counts[static_cast<int>(w.verdict)];
    char line[200];
    char hz[32] = "";
    if (w.verdict == milling::WindowVerdict::kChatter) std::snprintf(hz, sizeof hz, ", %.2f Hz", w.chatter_hz);
    std::snprintf(line, sizeof line, "  %7.2f-%7.2f s  %-17s  non-harmonic %5.1f %%%s\n", w.start_s, w.end_s,
                  milling::to_string(w.verdict), 100.0 * w.chatter_share, hz);
    t << line;
  }
  if (r.onset_s) {
    char head[320];
    std::snprintf(head, sizeof head,
                  "CHATTER from %.2f s to %.2f s at %.2f Hz (%zu of %zu windows; the same chatter as k x %.2f Hz +/- "
                  "%.2f Hz). Speeds to try (the tooth frequency at %.2f Hz / k):",
                  *r.onset_s, *r.end_s, r.chatter_hz, counts[1], r.windows.size(), r.rpm * a.teeth / 60.0,
                  milling::chatter_family_hz(r.chatter_hz, r.rpm * a.teeth / 60.0), r.chatter_hz);
    t << head;
    for (const auto& s : r.speeds) t << ' ' << std::lround(s.rpm) << " rpm (k " << s.lobe << ")";
    t << (r.speeds.empty() ? " none within the range" : "") << "\n";
    if (advice) t << checked_text(*advice, a.damped);
  } else {
    t << "NO CHATTER in " << counts[0] << " windows judged (" << counts[2] << " without enough signal)\n";
  }
  nlohmann::json j = to_json(r, a.teeth);
  if (advice) j["checked"] = checked_json(*advice, a.damped);
  return print_report(
      j.dump(2), a.json, "chatter", t.str(), a.plot_dir, [&] { return plots(r, a.plot_dir); },
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
