#include "identify/pose_measurements.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "analysis/modal_test.hpp"
#include "config/config.hpp"
#include "config/pose_schedule_config.hpp"
#include "identify/commissioning.hpp"
#include "identify/modal_fit.hpp"

namespace robodamp::identify {

namespace fs = std::filesystem;

namespace {

// A `measure --poses` directory stands for its poses, in its index's order.
std::vector<std::string> expand(const std::vector<std::string>& dirs) {
  std::vector<std::string> out;
  for (const auto& d : dirs) {
    const fs::path index = fs::path(d) / "poses.json";
    if (!fs::exists(index)) {
      out.push_back(d);
      continue;
    }
    std::ifstream in(index);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
      for (const auto& p : j.at("poses")) out.push_back((fs::path(d) / p.at("dir").get<std::string>()).string());
    } catch (const std::exception& e) {
      throw std::invalid_argument(index.string() + ": " + e.what());
    }
  }
  return out;
}

int driving_point(const MeasurementManifest& m, int location_id, const std::string& dir) {
  if (location_id != 0) return location_id;
  if (m.locations.empty()) throw std::invalid_argument(dir + ": the measurement names no location");
  for (const auto& [id, name] : m.locations)
    if (name == "TCP") return id;
  return m.locations.front().first;
}

// The largest receptance's frequency inside [lo, hi] (below the band an impact FRF is noise and drift).
double peak_hz(const robot::MeasuredFrf& f, double lo_hz, double hi_hz) {
  double best = -1.0, at = 0.0;
  for (std::size_t i = 0; i < f.freq_hz.size(); ++i)
    if (f.freq_hz[i] >= lo_hz && f.freq_hz[i] <= hi_hz && std::abs(f.receptance_m_per_n[i]) > best)
      best = std::abs(f.receptance_m_per_n[i]), at = f.freq_hz[i];
  return at;
}

bool same_pose(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t j = 0; j < a.size(); ++j)
    if (std::abs(a[j] - b[j]) > 0.5) return false;
  return true;
}

void check_consistent(const PoseMeasurements& r) {
  for (std::size_t i = 0; i < r.frfs.size(); ++i)
    for (std::size_t k = 0; k < i; ++k) {
      const auto &a = r.frfs[i], &b = r.frfs[k];
      if (a.name == b.name)
        throw std::invalid_argument(r.dirs[i] + " and " + r.dirs[k] + " both name the pose '" + a.name + "'");
      if (!same_pose(a.joints_deg, b.joints_deg)) continue;
      const double f = std::max(peak_hz(a, r.band_min_hz, r.band_max_hz), peak_hz(b, r.band_min_hz, r.band_max_hz));
      const double d = frf_difference(a, b, std::max(r.band_min_hz, 0.5 * f), std::min(r.band_max_hz, 2.0 * f));
      if (d > 0.2)
        throw std::invalid_argument(
            r.dirs[i] + " and " + r.dirs[k] + " were measured at the same pose " + config::describe_pose(a.joints_deg) +
            " and their FRFs differ by " + std::to_string(static_cast<int>(std::lround(100.0 * d))) + " % around the " +
            std::to_string(static_cast<int>(std::lround(f))) +
            " Hz peak: contradicting data (a robot moved, a loose mount?); measure that pose again");
    }
}

}  // namespace

void check_against_model(const PoseMeasurements& r, const config::RobotModelConfig& model) {
  constexpr double kMeasuredApart = 0.2, kTimesTheModel = 3.0;
  std::vector<robot::MeasuredFrf> modelled;  // the model at each pose, once, on its measurement's frequencies
  for (const auto& f : r.frfs)
    modelled.push_back(robot::model_frf(model, f, r.direction, r.band_min_hz, r.band_max_hz, r.modes));
  for (std::size_t i = 0; i < r.frfs.size(); ++i)
    for (std::size_t k = 0; k < i; ++k) {
      const auto &a = r.frfs[i], &b = r.frfs[k];
      const double f = std::max(peak_hz(a, r.band_min_hz, r.band_max_hz), peak_hz(b, r.band_min_hz, r.band_max_hz));
      const double lo = std::max(r.band_min_hz, 0.5 * f), hi = std::min(r.band_max_hz, 2.0 * f);
      const double d_model = frf_difference(modelled[i], modelled[k], lo, hi);
      const double d = frf_difference(a, b, lo, hi);
      if (d <= std::max(kMeasuredApart, kTimesTheModel * d_model)) continue;
      const auto pct = [](double v) { return std::to_string(static_cast<int>(std::lround(100.0 * v))) + " %"; };
      throw std::invalid_argument(r.dirs[i] + " (pose '" + a.name + "' " + config::describe_pose(a.joints_deg) +
                                  ") and " + r.dirs[k] + " (pose '" + b.name + "' " +
                                  config::describe_pose(b.joints_deg) + "): their measured FRFs differ by " + pct(d) +
                                  " around the " + std::to_string(static_cast<int>(std::lround(f))) +
                                  " Hz peak, more than 3 times the " + pct(d_model) + " the robot model " + model.name +
                                  " puts between the two poses: contradicting data (a pose read wrong, a robot moved, "
                                  "a loose mount?); measure one of them again");
    }
}

double frf_difference(const robot::MeasuredFrf& a, const robot::MeasuredFrf& b, double f_lo_hz, double f_hi_hz) {
  double peak = 0.0;
  for (std::size_t i = 0; i < a.freq_hz.size(); ++i)
    if (a.freq_hz[i] >= f_lo_hz && a.freq_hz[i] <= f_hi_hz) peak = std::max(peak, std::abs(a.receptance_m_per_n[i]));
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < a.freq_hz.size(); ++i) {
    const double f = a.freq_hz[i];
    if (f < f_lo_hz || f > f_hi_hz || b.freq_hz.size() < 2) continue;
    const auto it = std::lower_bound(b.freq_hz.begin(), b.freq_hz.end(), f);
    if (it == b.freq_hz.begin() || it == b.freq_hz.end()) continue;
    const auto k = static_cast<std::size_t>(it - b.freq_hz.begin());
    const double t = (f - b.freq_hz[k - 1]) / (b.freq_hz[k] - b.freq_hz[k - 1]);
    const std::complex<double> hb =
        b.receptance_m_per_n[k - 1] + t * (b.receptance_m_per_n[k] - b.receptance_m_per_n[k - 1]);
    const double w = peak > 0.0 ? std::abs(a.receptance_m_per_n[i]) / peak : 0.0;
    num += w * std::norm(a.receptance_m_per_n[i] - hb);
    den += w * std::norm(a.receptance_m_per_n[i]);
  }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

PoseMeasurements read_pose_measurements(const std::vector<std::string>& dirs, int location_id) {
  PoseMeasurements r;
  for (const std::string& dir : expand(dirs)) {
    const MeasurementManifest m = read_manifest(dir);  // throws naming the file
    if (m.pose_deg.empty())
      throw std::invalid_argument(dir +
                                  ": its measurement.json holds no joint angles (measured without --pose): the "
                                  "pose-indexed model needs the pose of every measurement; measure it again with "
                                  "robodamp measure --pose or --poses");
    const int id = driving_point(m, location_id, dir);
    const std::string csv = (fs::path(dir) / analysis::frf_file_name(id, id)).string();
    if (!fs::exists(csv))
      throw std::invalid_argument(dir + ": no " + fs::path(csv).filename().string() + " (location " +
                                  std::to_string(id) +
                                  "'s driving-point FRF; on hardware robodamp plant --measure-out writes it)");
    const FrfData d = read_frf_csv(csv, FrfKind::kReceptance);
    robot::MeasuredFrf f;
    f.name = m.pose_name.empty() ? fs::path(dir).filename().string() : m.pose_name;
    f.joints_deg = m.pose_deg;
    f.freq_hz = d.f_hz;
    f.receptance_m_per_n = d.h;
    r.frfs.push_back(std::move(f));
    r.dirs.push_back(dir);
    if (r.dirs.size() == 1) {
      r.robot_model = m.robot_model;
      const config::Config measured = config::parse_config(m.config_text, m.config_source);
      r.band_min_hz = measured.analysis.band_min_hz, r.band_max_hz = measured.analysis.band_max_hz;
      if (measured.pose_schedule) {
        r.direction = measured.pose_schedule->axis == 0 ? robot::FrfDirection::kXX : robot::FrfDirection::kYY;
        r.modes = measured.pose_schedule->modes;
      }
    } else if (m.robot_model != r.robot_model)
      throw std::invalid_argument(dir + ": measured against the robot model " + m.robot_model + ", " + r.dirs.front() +
                                  " against " + r.robot_model + ": one model's joints, one set of measurements");
  }
  if (r.frfs.empty()) throw std::invalid_argument("no measurement directory given");
  check_consistent(r);
  return r;
}

}  // namespace robodamp::identify
