// What `robodamp pose map` reports of a pose map (milling/pose_map.hpp): JSON, text and the plot.
#include <cmath>
#include <sstream>

#include "fields/printf.hpp"
#include "milling/pose_map.hpp"
#include "plot/gnuplot.hpp"

namespace robodamp::milling {

using nlohmann::json;

PoseMapReport pose_map_report(const config::RobotModelConfig& m, const PoseMapRequest& req, const PoseMap& map,
                              const std::string& job_path) {
  const int va = static_cast<int>(req.joint_a) + 1, vb = static_cast<int>(req.joint_b) + 1;
  json grid = json::array();
  std::ostringstream data;
  for (std::size_t i = 0; i < map.grid.size(); ++i) {
    const PoseMapPoint& p = map.grid[i];
    json point = {{"joints_deg", p.joints_deg}, {"f1_hz", p.f1_hz}, {"k1_n_per_m", p.k1_n_per_m}};
    if (p.min_depth_mm) point["min_depth_mm"] = *p.min_depth_mm, point["min_depth_rpm"] = *p.min_depth_rpm;
    grid.push_back(point);
    data << p.joints_deg[req.joint_a] << ' ' << p.joints_deg[req.joint_b] << ' ' << p.f1_hz << ' ' << p.k1_n_per_m
         << ' ' << p.min_depth_mm.value_or(NAN) << '\n';
    if ((i + 1) % static_cast<std::size_t>(req.steps) == 0) data << '\n';
  }
  PoseMapReport r;
  r.json = {{"model", m.source}, {"vary", std::vector<int>{va, vb}}, {"steps", req.steps},
            {"grid", grid},      {"f1_min_hz", map.f1_min_hz},       {"f1_max_hz", map.f1_max_hz}};
  r.text = fields::printf_string("robot %s: first mode over joints %d and %d (%d x %d poses): %.2f to %.2f Hz\n",
                                 m.name.c_str(), va, vb, req.steps, req.steps, map.f1_min_hz, map.f1_max_hz);
  if (req.job) {
    r.text += fields::printf_string("  %s: minimum limiting depth (open loop, %s, %g-%g rpm) %.3f to %.3f mm\n",
                                    job_path.c_str(), map.method.c_str(), req.job->lobes.rpm_min,
                                    req.job->lobes.rpm_max, map.min_depth_min_mm, map.min_depth_max_mm);
    r.json["method"] = map.method;
    r.json["min_depth_min_mm"] = map.min_depth_min_mm;
    r.json["min_depth_max_mm"] = map.min_depth_max_mm;
  }
  r.plot_data = data.str();
  return r;
}

std::string plot_pose_map(const PoseMapReport& r, const PoseMapRequest& req, const PoseMap& map,
                          const std::string& png_path) {
  const bool job = req.job != nullptr;
  const std::string s = "set terminal pngcairo size " + std::string(job ? "2000" : "1400") + ",600; set output '" +
                        png_path + "'; set multiplot layout 1," + std::string(job ? "3" : "2") +
                        "; set view map; set xlabel 'joint " + std::to_string(req.joint_a + 1) +
                        " (deg)'; set ylabel 'joint " + std::to_string(req.joint_b + 1) +
                        " (deg)'; set title 'first mode (Hz)'; splot DATA u 1:2:3 w pm3d notitle;"
                        " set title 'TCP modal stiffness of the first mode (N/m)'; set format cb '%.1e';"
                        " splot DATA u 1:2:4 w pm3d notitle;" +
                        std::string(job ? " set format cb '%g'; set title 'minimum limiting depth (mm, " + map.method +
                                              ")';"
                                              " splot DATA u 1:2:5 w pm3d notitle;"
                                        : "") +
                        " unset multiplot";
  return plot::run_gnuplot(s, r.plot_data, png_path);
}

}  // namespace robodamp::milling
