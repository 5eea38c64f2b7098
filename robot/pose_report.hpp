// What `robodamp pose frf` and `robodamp pose table` report of a robot model (docs/pose_dynamics.md): the
// TCP's modes and receptance at a pose, the first mode at each named pose, as JSON, text and the plot's
// data. Off the real-time path.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/robot_model_config.hpp"
#include "robot/planar_chain.hpp"
#include "robot/pose_fit.hpp"

namespace robodamp::robot {

struct PoseReport {
  nlohmann::json json;
  std::string text;
  std::string plot_data;  // pose frf: frequency, |xx|, |yy|, |xy| per line
};

[[nodiscard]] nlohmann::json modes_json(const std::vector<Mode>& modes);

// The model at joints q: the TCP, its lowest `modes` modes and its receptance on 400 log-spaced frequencies
// from f_lo_hz to f_hi_hz (direct assembly), with receptance coupling's largest relative difference from it.
[[nodiscard]] PoseReport pose_frf_report(const config::RobotModelConfig& m, const std::vector<double>& q,
                                         std::size_t modes, double f_lo_hz, double f_hi_hz);

// The receptance in one direction ("xx", "xy", "yy") every step_hz from f_lo_hz to f_hi_hz as the
// identification tools read it (freq_hz,re_m_per_n,im_m_per_n). False when the file cannot be written.
[[nodiscard]] bool write_frf_csv(const PlanarChain& c, double f_lo_hz, double f_hi_hz, double step_hz,
                                 const std::string& direction, const std::string& path);

// PoseReport::plot_data as the TCP's receptance in png_path: an empty string, or why the plot failed.
[[nodiscard]] std::string plot_pose_frf(const std::string& plot_data, const std::string& png_path);

// The first mode at each named pose beside the published values.
[[nodiscard]] PoseReport pose_table_report(const config::RobotModelConfig& m);

// `pose fit`'s report: the joints fitted (stiffness, spread, damping) and, at each pose fitted and held out,
// the model's error and the receptance's peak frequency before and after.
[[nodiscard]] PoseReport pose_fit_report(const config::RobotModelConfig& m, const PoseFitResult& r,
                                         const std::vector<MeasuredFrf>& fit, const std::vector<MeasuredFrf>& held,
                                         const PoseFitSettings& s);

}  // namespace robodamp::robot
