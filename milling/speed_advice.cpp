#include "milling/speed_advice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "config/pose_schedule_config.hpp"

namespace robodamp::milling {

namespace {

std::string number(double v, const char* format) {
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

// The modes of the structure the advice checks, once each: every part's and direction's, and, for the
// part the damper is on, the robot's in the loop's configuration (the active set's).
std::vector<double> mode_frequencies(const config::StructureConfig& s, const config::Config& loop) {
  std::set<long> seen;
  std::vector<double> out;
  auto add = [&](double f_hz) {
    if (f_hz > 0.0 && seen.insert(std::lround(f_hz * 100.0)).second) out.push_back(f_hz);
  };
  for (const auto& part : s.parts) {
    for (const auto& direction : part.modes)
      for (const auto& m : direction) add(m.natural_freq_hz);
    if (part.controller)
      for (const auto& frf : loop.robot.frfs)
        for (const auto& m : frf.modes) add(m.natural_freq_hz);
  }
  return out;
}

// A candidate's limit at every pose checked (the pose now first): the lowest, with its pose; not valid when
// the damped loop is unstable at any of them.
struct AlongPath {
  LiveLimits at_lowest;
  double limit_mm{0.0};
  std::vector<double> pose_deg;
  bool valid{true};
};

AlongPath limit_along(LiveStability& stability, const SpeedAdviceRequest& request,
                      const std::vector<std::vector<double>>& poses, double rpm) {
  AlongPath out;
  bool first = true;
  const auto now = request.controller_at ? request.controller_at(rpm) : std::pair{request.set, request.gain_ns_per_m};
  for (std::size_t i = 0; i < std::max<std::size_t>(poses.size(), 1); ++i) {
    const std::vector<double> pose = poses.empty() ? std::vector<double>{} : poses[i];
    const auto [set, gain] = i > 0 && request.controller_at_pose ? request.controller_at_pose(pose, rpm) : now;
    const LiveLimits l = stability.compute(rpm, set, gain, pose);
    if (request.damped && !l.damped_valid) {
      out.valid = false;
      out.at_lowest = l, out.pose_deg = pose;
      return out;
    }
    const double limit = request.damped ? l.damped_mm : l.open_mm;
    if (first || limit < out.limit_mm) out.at_lowest = l, out.limit_mm = limit, out.pose_deg = pose;
    first = false;
  }
  return out;
}

}  // namespace

std::vector<std::vector<double>> thin_path(const std::vector<std::vector<double>>& path, std::size_t count) {
  if (path.size() <= count) return path;
  std::vector<std::vector<double>> out;
  if (count == 0) return out;
  // Poses (size - 1) j / (count - 1), j = 0 .. count - 1: evenly along it, its first and last among them.
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t i = count == 1 ? path.size() - 1 : (path.size() - 1) * j / (count - 1);
    if (out.empty() || out.back() != path[i]) out.push_back(path[i]);
  }
  return out;
}

std::vector<SpeedCandidate> advice_candidates(double rpm_min, double rpm_max, int teeth, double chatter_hz,
                                              const std::vector<double>& mode_hz, std::size_t grid_points) {
  std::vector<SpeedCandidate> all;
  auto pockets = [&](double f_hz, const char* source) {
    // The tooth frequency at f / k: k = 1 is the highest pocket speed, then down to the range's bottom.
    for (int k = 1; k <= 1000; ++k) {
      const double rpm = 60.0 * f_hz / (static_cast<double>(teeth) * k);
      if (rpm < rpm_min) break;
      if (rpm <= rpm_max) all.push_back({rpm, source});
    }
  };
  if (chatter_hz > 0.0) pockets(chatter_hz, "chatter frequency");
  for (const double f : mode_hz) pockets(f, "mode");
  for (std::size_t i = 0; i < grid_points; ++i) {
    const double u = grid_points == 1 ? 0.5 : static_cast<double>(i) / static_cast<double>(grid_points - 1);
    all.push_back({rpm_min + u * (rpm_max - rpm_min), "grid"});
  }
  // Sorted by speed; of candidates within 0.5 rpm the first named keeps its source (chatter, mode, grid).
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.rpm < b.rpm; });
  std::vector<SpeedCandidate> out;
  for (const auto& c : all) {
    if (!out.empty() && c.rpm - out.back().rpm < 0.5) {
      auto rank = [](const std::string& s) { return s == "chatter frequency" ? 0 : s == "mode" ? 1 : 2; };
      if (rank(c.source) < rank(out.back().source)) out.back().source = c.source;
      continue;
    }
    out.push_back(c);
  }
  return out;
}

SpeedAdvice advise_speed(LiveStability& stability, const SpeedAdviceRequest& request, double rpm_min, double rpm_max,
                         const SpeedAdviceSettings& s) {
  if (!(std::isfinite(request.rpm) && request.rpm > 0.0))
    throw std::invalid_argument("speed advice: spindle speed " + number(request.rpm, "%g") +
                                " rpm; it must be finite and above 0 rpm");
  if (!(std::isfinite(request.depth_mm) && request.depth_mm > 0.0))
    throw std::invalid_argument("speed advice: depth " + number(request.depth_mm, "%g") +
                                " mm; it must be finite and above 0 mm");
  if (!(rpm_min > 0.0 && rpm_max >= rpm_min))
    throw std::invalid_argument("speed advice: speed range " + number(rpm_min, "%g") + ".." + number(rpm_max, "%g") +
                                " rpm; it must be positive and not empty");
  const auto start = std::chrono::steady_clock::now();
  SpeedAdvice a;
  a.request = request;
  a.rpm_min = rpm_min;
  a.rpm_max = rpm_max;
  auto limit_of = [&](const LiveLimits& l) { return request.damped ? l.damped_mm : l.open_mm; };
  const LiveLimits now = stability.compute(request.rpm, request.set, request.gain_ns_per_m, request.pose_deg);
  a.limit_now_mm = limit_of(now);
  a.method = request.damped ? now.method : now.open_method;
  a.depth_mm = request.depth_mm;
  if (request.chatter_hz > 0.0 && a.limit_now_mm > request.depth_mm)
    a.depth_mm = a.limit_now_mm, a.depth_from_chatter = true;
  const double margin = a.depth_from_chatter ? s.chatter_depth_margin : s.depth_margin;
  const int teeth = stability.job().tool.teeth;
  if (!request.pose_deg.empty()) {
    a.poses_checked.push_back(request.pose_deg);
    for (auto& p : thin_path(request.path_ahead_deg, s.max_path_poses))
      if (p != request.pose_deg) a.poses_checked.push_back(std::move(p));
  }
  // The pockets of the modes at every pose checked.
  std::vector<double> modes;
  for (std::size_t i = 0; i < std::max<std::size_t>(a.poses_checked.size(), 1); ++i) {
    const std::vector<double> pose = a.poses_checked.empty() ? std::vector<double>{} : a.poses_checked[i];
    for (const double f : mode_frequencies(stability.structure(), stability.loop_config(request.set, pose)))
      if (std::none_of(modes.begin(), modes.end(), [&](double g) { return std::abs(g - f) < 0.005; }))
        modes.push_back(f);
  }
  std::vector<SpeedOption> qualified;
  a.best.margin = -1.0;
  for (const SpeedCandidate& c : advice_candidates(rpm_min, rpm_max, teeth, request.chatter_hz, modes, s.grid_points)) {
    if (s.cancelled && s.cancelled()) {
      a.reason = "cancelled after " + std::to_string(a.evaluated) + " speeds";
      return a;
    }
    const AlongPath l = limit_along(stability, request, a.poses_checked, c.rpm);
    ++a.evaluated;
    if (!l.valid) continue;  // the loop itself unstable there (at a pose checked)
    // The damped verdict is for the speed the sampled loop steps (whole loop periods per tooth period).
    const SpeedOption o{request.damped ? l.at_lowest.analysed_rpm : l.at_lowest.rpm, l.limit_mm,
                        l.limit_mm / a.depth_mm, c.source, l.pose_deg};
    if (o.margin > a.best.margin) a.best = o;
    if (o.margin >= margin && std::abs(o.rpm - request.rpm) > 0.5) qualified.push_back(o);
  }
  std::stable_sort(qualified.begin(), qualified.end(), [&](const SpeedOption& x, const SpeedOption& y) {
    return std::abs(x.rpm - request.rpm) < std::abs(y.rpm - request.rpm);
  });
  if (qualified.size() > s.max_options) qualified.resize(s.max_options);
  a.options = std::move(qualified);
  a.found = !a.options.empty();
  if (!a.found)
    a.reason = "no speed in " + number(rpm_min, "%.0f") + ".." + number(rpm_max, "%.0f") + " rpm is stable at " +
               number(a.depth_mm, "%.3f") + " mm" + (a.depth_from_chatter ? " (the limit where it chatters)" : "") +
               " with " + number(100.0 * (margin - 1.0), "%.0f") + " % margin (" + std::to_string(a.evaluated) +
               " speeds analysed; the best, " + number(a.best.rpm, "%.0f") + " rpm, allows " +
               number(a.best.limit_mm, "%.3f") + " mm" +
               (a.poses_checked.size() > 1 ? " at " + config::describe_pose(a.best.limiting_pose_deg) : std::string()) +
               "): reduce the depth" +
               (a.poses_checked.size() > 1 ? " (checked at the pose now and " +
                                                 std::to_string(a.poses_checked.size() - 1) + " of the path ahead)"
                                           : std::string());
  a.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return a;
}

}  // namespace robodamp::milling
