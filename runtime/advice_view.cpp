#include "runtime/advice_view.hpp"

#include <cmath>
#include <cstdio>

#include "config/pose_schedule_config.hpp"

namespace robodamp::runtime {

std::string advice_text(const dds::AdviceSample& a) {
  char b[512];
  std::string chatter;
  if (a.chatter_hz > 0.0)
    chatter = ", chatter at " + std::to_string(static_cast<int>(std::lround(a.chatter_hz))) + " Hz";
  std::snprintf(b, sizeof b,
                "  speed advice #%llu at %.3f s (%s at %.0f rpm%s; %.3f mm against a %s limit of %.3f mm, %s):",
                static_cast<unsigned long long>(a.seq), a.time_s, a.trigger.c_str(), a.spindle_rpm, chatter.c_str(),
                a.depth_mm, a.damped ? "damped" : "open-loop", a.limit_now_mm, a.method.c_str());
  std::string out = b;
  if (!a.pose_deg.empty()) {
    out += " at the robot's pose " + config::describe_pose(a.pose_deg);
    if (a.poses_ahead > 0)
      out +=
          " and " + std::to_string(a.poses_ahead) + " pose" + (a.poses_ahead == 1 ? "" : "s") + " of the path ahead" +
          (a.limiting_pose_deg.empty() ? std::string()
                                       : " (the lowest limit at " + config::describe_pose(a.limiting_pose_deg) + ")");
    out += ":";
  }
  const std::string status = a.status == "current" ? "" : " [" + a.status + ": " + a.status_reason + "]";
  if (!a.found) return out + " " + a.reason + status + "\n";
  for (std::size_t i = 0; i < a.option_rpm.size(); ++i) {
    std::snprintf(b, sizeof b, "%s %.0f rpm (%.3f mm, margin %.2f)", i == 0 ? "" : ";", a.option_rpm[i],
                  a.option_limit_mm[i], a.option_limit_mm[i] / a.depth_mm);
    out += b;
  }
  return out + status + "\n";
}

nlohmann::json advice_json(const dds::AdviceSample& a) {
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json options = nlohmann::json::array();
  for (std::size_t i = 0; i < a.option_rpm.size(); ++i)
    options.push_back({{"rpm", a.option_rpm[i]}, {"limit_mm", finite(a.option_limit_mm[i])}});
  return {{"seq", a.seq},
          {"time_s", a.time_s},
          {"trigger", a.trigger},
          {"spindle_rpm", a.spindle_rpm},
          {"depth_mm", a.depth_mm},
          {"damped", a.damped},
          {"chatter_hz", a.chatter_hz},
          {"limit_now_mm", finite(a.limit_now_mm)},
          {"method", a.method},
          {"found", a.found},
          {"advised_rpm", a.advised_rpm},
          {"advised_limit_mm", finite(a.advised_limit_mm)},
          {"margin", finite(a.margin)},
          {"options", options},
          {"best_rpm", a.best_rpm},
          {"best_limit_mm", finite(a.best_limit_mm)},
          {"reason", a.reason},
          {"rpm_min", a.rpm_min},
          {"rpm_max", a.rpm_max},
          {"pose_deg", a.pose_deg},
          {"poses_ahead", a.poses_ahead},
          {"limiting_pose_deg", a.limiting_pose_deg},
          {"status", a.status},
          {"status_reason", a.status_reason}};
}

}  // namespace robodamp::runtime
