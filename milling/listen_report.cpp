#include "milling/listen_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "milling/chatter.hpp"
#include "milling/live_stability.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::milling {

namespace {

nlohmann::json windows_json(const ListenReport& r, int teeth) {
  const double tooth_hz = r.rpm * teeth / 60.0;  // the chatter's family: milling/chatter.hpp
  nlohmann::json w = nlohmann::json::array();
  for (const auto& x : r.windows)
    w.push_back({{"start_s", x.start_s},
                 {"end_s", x.end_s},
                 {"verdict", to_string(x.verdict)},
                 {"chatter_hz", x.chatter_hz},
                 {"chatter_family_hz", chatter_family_hz(x.chatter_hz, tooth_hz)},
                 {"chatter_share", x.chatter_share},
                 {"rms", x.rms},
                 {"once_per_rev_ratio", x.indicator.once_per_rev_ratio},
                 {"rpm", x.rpm}});
  nlohmann::json speeds = nlohmann::json::array();
  for (const auto& s : r.speeds) speeds.push_back({{"rpm", s.rpm}, {"lobe", s.lobe}});
  nlohmann::json j = {{"windows", w},
                      {"chatter_hz", r.chatter_hz},
                      {"chatter_family_hz", chatter_family_hz(r.chatter_hz, tooth_hz)},
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

std::string checked_text(const SpeedAdvice& advice, bool damped) {
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

nlohmann::json checked_json(const SpeedAdvice& advice, bool damped) {
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

}  // namespace

std::string listen_text(const ListenReport& r, int teeth, const std::string& signal,
                        const std::optional<SpeedAdvice>& advice, bool damped) {
  std::ostringstream t;
  t << "robodamp chatter: " << signal << ", " << r.samples << " samples at " << r.rate_hz << " Hz, analysed at "
    << r.analysed_rate_hz << " Hz\n  spindle " << r.rpm << " rpm (" << r.rpm_source << ")\n";
  for (const auto& w : r.warnings) t << "  NOTE: " << w << '\n';
  std::size_t counts[3] = {0, 0, 0};
  for (const auto& w : r.windows) {
    ++counts[static_cast<int>(w.verdict)];
    char line[200];
    char hz[32] = "";
    if (w.verdict == WindowVerdict::kChatter) std::snprintf(hz, sizeof hz, ", %.2f Hz", w.chatter_hz);
    std::snprintf(line, sizeof line, "  %7.2f-%7.2f s  %-17s  non-harmonic %5.1f %%%s\n", w.start_s, w.end_s,
                  to_string(w.verdict), 100.0 * w.chatter_share, hz);
    t << line;
  }
  if (r.onset_s) {
    char head[320];
    std::snprintf(head, sizeof head,
                  "CHATTER from %.2f s to %.2f s at %.2f Hz (%zu of %zu windows; the same chatter as k x %.2f Hz +/- "
                  "%.2f Hz). Speeds to try (the tooth frequency at %.2f Hz / k):",
                  *r.onset_s, *r.end_s, r.chatter_hz, counts[1], r.windows.size(), r.rpm * teeth / 60.0,
                  chatter_family_hz(r.chatter_hz, r.rpm * teeth / 60.0), r.chatter_hz);
    t << head;
    for (const auto& s : r.speeds) t << ' ' << std::lround(s.rpm) << " rpm (k " << s.lobe << ")";
    t << (r.speeds.empty() ? " none within the range" : "") << "\n";
    if (advice) t << checked_text(*advice, damped);
  } else {
    t << "NO CHATTER in " << counts[0] << " windows judged (" << counts[2] << " without enough signal)\n";
  }
  return t.str();
}

nlohmann::json listen_json(const ListenReport& r, int teeth, const std::optional<SpeedAdvice>& advice, bool damped) {
  nlohmann::json j = windows_json(r, teeth);
  if (advice) j["checked"] = checked_json(*advice, damped);
  return j;
}

std::string plot_listen(const ListenReport& r, const std::string& dir) {
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
  if (auto e = plot::run_gnuplot(s.str(), sp.str(), dir + "/chatter_spectrogram.png"); !e.empty()) return e;
  std::ostringstream v;
  for (const auto& w : r.windows) {
    const int level = w.verdict == WindowVerdict::kChatter ? 2 : w.verdict == WindowVerdict::kStable ? 1 : 0;
    const double mid_s = 0.5 * (w.start_s + w.end_s);  // where the window's chatter frequency is drawn
    v << plot::num(w.start_s) << ' ' << level << ' ' << plot::num(w.chatter_share) << ' ' << plot::num(w.chatter_hz)
      << ' ' << plot::num(mid_s) << '\n'
      << plot::num(w.end_s) << ' ' << level << ' ' << plot::num(w.chatter_share) << ' ' << plot::num(w.chatter_hz)
      << ' ' << plot::num(mid_s) << '\n';
  }
  const bool chattered =
      std::any_of(r.windows.begin(), r.windows.end(), [](const auto& w) { return w.chatter_hz > 0.0; });
  std::string onset;
  if (r.onset_s)
    onset = "set arrow from " + plot::num(*r.onset_s) + ", graph 0 to " + plot::num(*r.onset_s) +
            ", graph 1 nohead dt 2 lc rgb 'red'\nset label 'onset " +
            plot::num(std::round(*r.onset_s * 100.0) / 100.0) + " s' at " + plot::num(*r.onset_s) +
            ", graph 0.9 offset 0.5,0 tc rgb 'red'\n";
  const std::string s2 =
      "set multiplot layout 2,1 title 'Chatter over time'\nset lmargin at screen 0.14\nset rmargin at screen 0.9\nset "
      "grid\nset ylabel 'verdict'\n" +
      onset +
      "set ytics ('not enough signal' 0, 'stable' 1, 'chatter' 2)\nset yrange [-0.3:2.3]\n"
      "plot DATA u 1:2 w l lw 3 t 'verdict per window'\nset ytics auto\nset yrange [*:*]\nset xlabel 'time (s)'\n"
      "set key bottom right\nset ylabel 'non-harmonic share'\nset yrange [-0.03:1.05]\n" +
      // The chatter frequency on the right axis where a window found one (a recording without chatter has
      // none to draw: gnuplot refuses an axis with no point on it).
      (chattered ? "set y2label 'chatter frequency (Hz)'\nset y2tics\nset y2range [0:*]\n"
                   "plot DATA u 1:3 w l t 'non-harmonic share of the energy', DATA u 5:($4 > 0 ? $4 : 1/0) axes x1y2 "
                   "w p pt 7 t 'chatter frequency (per window)'\n"
                 : "plot DATA u 1:3 w l t 'non-harmonic share of the energy (no window chattered)'\n") +
      "unset multiplot\n";
  return plot::run_gnuplot(s2, v.str(), dir + "/chatter_verdict.png");
}

std::optional<ListenCell> listen_cell(const std::string& config_path, const std::string& job_path, bool needs_cell,
                                      int teeth) {
  if (config_path.empty()) {
    if (!job_path.empty() || needs_cell)
      throw std::invalid_argument("--job, --depth-mm and --damped need --config (the cell)");
    return std::nullopt;
  }
  config::Config cfg = config::load_config_file(config_path);
  const std::string path = !job_path.empty() ? job_path : cfg.spindle.job_resolved;
  if (path.empty()) throw std::invalid_argument(config_path + ": no spindle.job: give --job");
  ListenCell c{std::move(cfg), config::load_milling_config(path)};
  if (c.job.tool.teeth != teeth)
    throw std::invalid_argument("--teeth " + std::to_string(teeth) + " but the job " + path +
                                " cuts with tool.teeth = " + std::to_string(c.job.tool.teeth));
  return c;
}

SpeedAdvice checked_speeds(const ListenCell& c, const ListenReport& r, std::optional<double> depth_mm, bool damped,
                           double rpm_lo, double rpm_hi) {
  config::MillingConfig job = c.job;
  SpeedAdviceRequest q;
  q.rpm = r.rpm, q.depth_mm = depth_mm.value_or(job.cut.axial_mm), q.set = 0,
  q.gain_ns_per_m = c.cfg.controller.gain_ns_per_m;
  q.damped = damped, q.chatter_hz = r.chatter_hz, q.trigger = "chatter";
  LiveStability stability(std::move(job), c.cfg.spindle.structure, {c.cfg});
  return advise_speed(stability, q, rpm_lo, rpm_hi);
}

}  // namespace robodamp::milling
