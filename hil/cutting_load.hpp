// The HIL emulator's spindle and cut (docs/harmonic_notch.md, "HIL cutting forces"): the spindle speed
// over the run (steps and linear ramps, plant time), published on the robot's spindle register as the
// robot controller would, and a milling job's periodic cutting force at the tooth-passing harmonics on
// the plant at that speed (sim::ToothPassingForce, harmonics from milling::force_spectrum). It measures
// what the notch bank is for: the amplifier command's component at each tooth harmonic (a lock-in on the
// tooth phase, so it holds through a ramp) and the time the actuator spends at its voltage or force limit
// while cutting. Built before the run (allocates); step() is allocation-free.
#pragma once

#include <complex>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "sim_plant/excitation.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::hil {

// The spindle speed over plant time: each change starts at t0_s and reaches rpm at t1_s (t1_s = t0_s: a step).
struct SpindleChange {
  double t0_s{0.0}, t1_s{0.0}, rpm{0.0};
};

class SpindleProfile {
 public:
  explicit SpindleProfile(std::vector<SpindleChange> changes);
  [[nodiscard]] double rpm(double t_s) const;
  [[nodiscard]] bool empty() const { return changes_.empty(); }

 private:
  std::vector<SpindleChange> changes_;  // by t0_s
};

// The cut: a job's force harmonics in the direction the plant models, at a location.
struct CutLoad {
  std::string job;          // the milling job it came from
  std::size_t location{0};  // plant location index
  int teeth{3};
  std::vector<std::complex<double>> harmonics_n;  // c_0 (mean) .. c_K, one-sided (F = Re sum c_k e^{i k phi})
};
// From a milling job file (its tool, material and cut; the wall-normal force at the location of its
// controller part). Throws config::ConfigError when the job cannot be read or has no controller part.
[[nodiscard]] CutLoad cut_load_from_job(const std::string& job_path, const sim::PlantModel& model, int harmonics);

struct CuttingReport {
  bool cut{false};
  std::string job;
  int teeth{0};
  double in_cut_s{0.0};
  double measured_s{0.0};          // of it at a steady speed (the lock-in's span)
  double saturated_in_cut_s{0.0};  // periods with the amplifier at its voltage range or the coil at its force limit
  std::vector<double> force_harmonics_n;    // |c_k|, k = 1..
  std::vector<double> command_harmonics_v;  // amplitude of the command at k x the tooth frequency, k = 1..
  double last_rpm{0.0};
};

class CuttingLoad {
 public:
  // The force joins the plant's excitations (none without a cut).
  CuttingLoad(sim::Plant& plant, std::optional<CutLoad> cut, SpindleProfile profile, int measured_harmonics = 3,
              double steady_s = 2.0);
  // Before the plant steps at plant time t: the speed now (the caller publishes it on the register).
  double before_step(double t_s) noexcept;
  // After it, with the command the amplifier applied and whether the amplifier is on.
  void after_step(double applied_v, double dt_s) noexcept;
  [[nodiscard]] CuttingReport report() const;

 private:
  sim::Plant& plant_;
  std::optional<CutLoad> cut_;
  SpindleProfile profile_;
  sim::ToothPassingForce* force_{nullptr};
  double steady_s_;
  double rpm_{0.0}, phase_start_{0.0}, steady_since_s_{0.0}, t_s_{0.0};
  std::vector<std::complex<double>> lockin_;
  std::uint64_t lockin_n_{0};
  double in_cut_s_{0.0}, measured_s_{0.0}, saturated_s_{0.0};
  std::uint64_t clipped_{0}, limited_{0};
};

[[nodiscard]] nlohmann::json cutting_json(const CuttingReport& r);

}  // namespace robodamp::hil
