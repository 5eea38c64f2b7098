#include "robot/pose_report.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "config/number_range.hpp"
#include "plot/gnuplot.hpp"
#include "robot/robot_model.hpp"

namespace robodamp::robot {

using nlohmann::json;

json modes_json(const std::vector<Mode>& modes) {
  json out = json::array();
  for (const auto& md : modes)
    out.push_back({{"freq_hz", md.freq_hz},
                   {"tcp_modal_stiffness_n_per_m", md.tcp_modal_stiffness_n_per_m},
                   {"tcp_direction_deg", md.tcp_direction_rad * 180.0 / M_PI}});
  return out;
}

PoseReport pose_frf_report(const config::RobotModelConfig& m, const std::vector<double>& q, std::size_t modes_wanted,
                           double f_lo_hz, double f_hi_hz) {
  const PlanarChain c = at_pose(m, q);
  const auto modes = c.modes(modes_wanted);
  PoseReport out;
  json& r = out.json;
  r = {{"model", m.source},
       {"joints_deg", q},
       {"tcp_m", {c.tcp_position_m().x(), c.tcp_position_m().y()}},
       {"modes", modes_json(modes)}};
  // The FRF on a log grid across the band, direct; RCSA's largest difference from it reported.
  json frf = json::array();
  double worst = 0.0;
  std::ostringstream data;
  for (double f = f_lo_hz; f <= f_hi_hz * 1.0001; f *= std::pow(f_hi_hz / f_lo_hz, 1.0 / 399.0)) {
    const Eigen::Matrix2cd g = c.tcp_frf_direct(f), h = c.tcp_frf_rcsa(f);
    worst = std::max(worst, (g - h).norm() / g.norm());
    frf.push_back({{"freq_hz", f},
                   {"xx", {g(0, 0).real(), g(0, 0).imag()}},
                   {"xy", {g(0, 1).real(), g(0, 1).imag()}},
                   {"yy", {g(1, 1).real(), g(1, 1).imag()}}});
    data << f << ' ' << std::abs(g(0, 0)) << ' ' << std::abs(g(1, 1)) << ' ' << std::abs(g(0, 1)) << '\n';
  }
  r["frf_m_per_n"] = frf;
  r["rcsa_max_relative_difference"] = worst;
  out.plot_data = data.str();
  std::ostringstream t;
  char b[200];
  std::snprintf(b, sizeof b, "robot %s at joints", m.name.c_str());
  t << b;
  for (double v : q) t << ' ' << v;
  std::snprintf(b, sizeof b, " deg: TCP at (%.3f, %.3f) m\n", c.tcp_position_m().x(), c.tcp_position_m().y());
  t << b << "  mode   freq Hz   TCP modal stiffness N/m   TCP direction deg\n";
  for (std::size_t i = 0; i < modes.size(); ++i) {
    std::snprintf(b, sizeof b, "  %4zu  %8.3f   %22.4g   %17.1f\n", i + 1, modes[i].freq_hz,
                  modes[i].tcp_modal_stiffness_n_per_m, modes[i].tcp_direction_rad * 180.0 / M_PI);
    t << b;
  }
  std::snprintf(b, sizeof b, "  TCP FRF %g-%g Hz: receptance coupling (RCSA) within %.2g of the assembled model\n",
                f_lo_hz, f_hi_hz, worst);
  t << b;
  out.text = t.str();
  return out;
}

bool write_frf_csv(const PlanarChain& c, double f_lo_hz, double f_hi_hz, double step_hz, const std::string& direction,
                   const std::string& path) {
  std::ofstream csv(path);
  csv << "freq_hz,re_m_per_n,im_m_per_n\n";
  csv.precision(12);
  const int row = direction == "xx" ? 0 : 1, col = direction == "yy" ? 1 : 0;
  for (double f = f_lo_hz; f <= f_hi_hz * 1.0001; f += step_hz) {
    const std::complex<double> h = c.tcp_frf_direct(f)(row, col);
    csv << f << ',' << h.real() << ',' << h.imag() << '\n';
  }
  return static_cast<bool>(csv);
}

std::string plot_pose_frf(const std::string& plot_data, const std::string& png_path) {
  const std::string s =
      "set terminal pngcairo size 900,600; set output '" + png_path +
      "'; set logscale xy; set grid; set xlabel 'frequency (Hz)'; set ylabel '|receptance| (m/N)';"
      " set title 'TCP receptance at the pose'; plot DATA u 1:2 w l lw 2 t 'xx', '' u 1:3 w l lw 2 t 'yy',"
      " '' u 1:4 w l t 'xy'";
  return plot::run_gnuplot(s, plot_data, png_path);
}

PoseReport pose_table_report(const config::RobotModelConfig& m) {
  json rows = json::array();
  std::ostringstream t;
  t << "robot " << m.name
    << ": the first mode at each named pose\n  pose        joints deg                    model Hz  "
       "published predicted Hz  measured Hz\n";
  for (const auto& p : m.poses) {
    const PlanarChain c = at_pose(m, p.joints_deg);
    const auto modes = c.modes(3);
    char b[240];
    std::string q;
    for (double v : p.joints_deg) {
      if (!q.empty()) q += ' ';
      q += config::format_number(v);
    }
    std::snprintf(b, sizeof b, "  %-10s  %-28s  %8.2f  %22s  %11s\n", p.name.c_str(), q.c_str(), modes[0].freq_hz,
                  p.predicted_f1_hz ? config::format_number(*p.predicted_f1_hz).c_str() : "-",
                  p.measured_f1_hz ? config::format_number(*p.measured_f1_hz).c_str() : "-");
    t << b;
    rows.push_back({{"name", p.name},
                    {"joints_deg", p.joints_deg},
                    {"modes", modes_json(modes)},
                    {"predicted_f1_hz", p.predicted_f1_hz ? json(*p.predicted_f1_hz) : json(nullptr)},
                    {"measured_f1_hz", p.measured_f1_hz ? json(*p.measured_f1_hz) : json(nullptr)}});
  }
  return {json{{"model", m.source}, {"poses", rows}}, t.str(), ""};
}

namespace {

// Each pose: its role, the model's error before and after the fit, the receptance's peak frequency.
nlohmann::json pose_rows(const config::RobotModelConfig& nominal, const config::RobotModelConfig& fitted,
                         const std::vector<MeasuredFrf>& data, const PoseFitSettings& s, const char* role,
                         std::ostringstream& t) {
  nlohmann::json rows = nlohmann::json::array();
  if (data.empty()) return rows;
  const std::vector<double> before = model_errors(nominal, data, s), after = model_errors(fitted, data, s);
  const std::vector<double> f_data = peak_hz(nullptr, data, s), f_before = peak_hz(&nominal, data, s),
                            f_after = peak_hz(&fitted, data, s);
  char b[240];
  for (std::size_t p = 0; p < data.size(); ++p) {
    std::snprintf(b, sizeof b, "  %-10s %-30s %-9s %9.2f %9.2f   %8.2f %8.2f %8.2f\n", data[p].name.c_str(),
                  config::describe_pose(data[p].joints_deg).c_str(), role, 100.0 * before[p], 100.0 * after[p],
                  f_data[p], f_before[p], f_after[p]);
    t << b;
    rows.push_back({{"frf", data[p].name},
                    {"joints_deg", data[p].joints_deg},
                    {"role", role},
                    {"nominal_error_pct", 100.0 * before[p]},
                    {"error_pct", 100.0 * after[p]},
                    {"peak_hz", f_data[p]},
                    {"nominal_peak_hz", f_before[p]},
                    {"fitted_peak_hz", f_after[p]}});
  }
  return rows;
}

}  // namespace

PoseReport pose_fit_report(const config::RobotModelConfig& m, const PoseFitResult& r,
                           const std::vector<MeasuredFrf>& fit, const std::vector<MeasuredFrf>& held,
                           const PoseFitSettings& s) {
  const char* dir = s.direction == FrfDirection::kXX ? "xx" : s.direction == FrfDirection::kXY ? "xy" : "yy";
  std::ostringstream t;
  char b[240];
  const std::string form = s.modes > 0 ? "its " + std::to_string(s.modes) + " lowest modes" : "its own receptance";
  std::snprintf(b, sizeof b,
                "robot %s (as %s) fitted to %zu FRF(s) (%s, %g-%g Hz): %d evaluations, %d of %d restarts converged\n",
                m.name.c_str(), form.c_str(), fit.size(), dir, s.band_min_hz, s.band_max_hz, r.evaluations,
                r.converged_restarts, s.restarts);
  t << b << "  joint   stiffness N m/rad   spread %   damping ratio\n";
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < r.stiffness_nm_per_rad.size(); ++j) {
    std::snprintf(b, sizeof b, "  %5zu   %17.5g   %8.3f   %13.4f\n", j + 1, r.stiffness_nm_per_rad[j],
                  r.stiffness_spread_pct[j], r.damping_ratio[j]);
    t << b;
    joints.push_back({{"stiffness_nm_per_rad", r.stiffness_nm_per_rad[j]},
                      {"spread_pct", r.stiffness_spread_pct[j]},
                      {"damping_ratio", r.damping_ratio[j]}});
  }
  t << "  the TCP receptance against the model file as given (nominal) and fitted: the weighted relative error and\n"
       "  the frequency of the largest receptance in the band\n";
  std::snprintf(b, sizeof b, "  %-10s %-30s %-9s %19s   %26s\n  %-10s %-30s %-9s %9s %9s   %8s %8s %8s\n", "", "", "",
                "error %", "peak Hz", "pose", "joints", "role", "nominal", "fitted", "measured", "nominal", "fitted");
  t << b;
  nlohmann::json poses = pose_rows(m, r.fitted, fit, s, "fit", t);
  for (auto& row : pose_rows(m, r.fitted, held, s, "held out", t)) poses.push_back(std::move(row));
  PoseReport out;
  out.json = {{"model", m.source},
              {"direction", dir},
              {"modes", s.modes},
              {"joints", joints},
              {"poses", poses},
              {"restart_costs", r.restart_costs},
              {"evaluations", r.evaluations},
              {"converged_restarts", r.converged_restarts}};
  out.text = t.str();
  return out;
}

}  // namespace robodamp::robot
