// The commissioning measurement's timeline and its plant side (docs/identification.md, "Commissioning").
// robodamp measure runs the loop with control off and the amplifier enabled: from settle_s a periodic
// chirp on the actuator (the supervisor's test signal), then, after a quiet gap, hammer impacts at every
// configured location in turn, each answered by measurement accelerometers at every location. The
// controller and the plant side (the simulated plant in process, or the HIL emulator in its own
// process) read the same plan from the configuration, so they agree on it without talking.
// Off the real-time path except before_step / after_step.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "analysis/bench_run.hpp"
#include "analysis/spectral.hpp"
#include "config/config.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::analysis {

struct CommissioningPlan {
  double chirp_start_s{0.0}, chirp_end_s{0.0};
  double chirp_amplitude_v{0.0};
  double predicted_peak_force_n{0.0};   // by the configured actuator (Eq. 3) at the chirp's amplitude
  std::vector<double> impacts_start_s;  // per location index: the first record's earliest start
  double duration_s{0.0};               // the run: every record complete, plus a second
};

// The plan for a configuration: the chirp's amplitude keeps the configured actuator's predicted force
// and the voltage inside chirp_force_fraction of their limits over the swept band.
[[nodiscard]] CommissioningPlan commissioning_plan(const config::Config& cfg, const sim::PlantModel& model);

// The plant side: one impact campaign per location (analysis/bench_run.hpp: irregular, seeded gaps,
// the hammer's load cell and modal-grade accelerometers at every location, rectangular records).
class ModalTest {
 public:
  // Schedules every hammer on the plant (allocates).
  ModalTest(const config::Config& cfg, sim::Plant& plant, const CommissioningPlan& plan);
  ModalTest(const ModalTest&) = delete;
  ModalTest& operator=(const ModalTest&) = delete;

  // Plant period k (index from 0), around plant.step(). RT-safe.
  void before_step(std::size_t k) noexcept;
  void after_step(std::size_t k) noexcept;
  [[nodiscard]] bool done(std::size_t k) const;
  [[nodiscard]] int records() const;
  [[nodiscard]] int records_planned() const;

  // [excitation location][response location]: H1 receptance with coherence.
  [[nodiscard]] std::vector<std::vector<FrfEstimate>> receptance() const;
  // frf_<response id>_<excitation id>.csv per pair (freq_hz,re_m_per_n,im_m_per_n,coherence, receptance),
  // up to analysis.band_max_hz x 1.5. Returns the file names. Throws std::runtime_error on a write error.
  std::vector<std::string> write_frf_csvs(const std::string& dir) const;

 private:
  config::Config cfg_;  // bench.averages / record_s from the commissioning section
  const sim::PlantModel& model_;
  std::vector<std::unique_ptr<ImpactCampaign>> campaigns_;  // per location
};

// The FRF file name for a pair of location ids.
[[nodiscard]] std::string frf_file_name(int response_id, int excitation_id);

}  // namespace robodamp::analysis
