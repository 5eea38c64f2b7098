// Verification on the cell (docs/identification.md, "robodamp commission"): the tuned controller run on
// the cell itself, not on the identified model. Impact tests at every location with control off and on,
// through the runtime cell (loop, supervisor, arming, gain ramp) as `robodamp measure` runs it, give the
// measured improvement of the dynamic stiffness at each identified FRF's peak beside what the identified
// model predicts; the damped cut's critical depth in time (the real Controller on the cell's plant) at
// the promise's speeds beside the promise. Off the real-time path.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "analysis/spectral.hpp"
#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "tune/verification.hpp"

namespace robodamp::commission {

struct FrfCheck {
  std::string name;
  int response_id{0}, excitation_id{0};
  double measured_improvement_pct{0.0}, predicted_improvement_pct{0.0};
  double open_peak_m_per_n{0.0}, closed_peak_m_per_n{0.0};
  double open_peak_hz{0.0}, closed_peak_hz{0.0};
  double coherence_min{0.0};
  // |H| over the analysis band, m/N: measured on the cell and predicted by the identified, tuned model.
  std::vector<double> f_hz, measured_open, measured_closed, predicted_open, predicted_closed;
};

// Through the HIL emulator: the regenerative cut at one speed and depth with the tuned controller.
struct CutTrial {
  double requested_rpm{0.0}, rpm{0.0};  // rpm: the emulator's (a whole number of loop periods per tooth)
  double depth_mm{0.0};
  bool complete{false}, stable{false};
  std::string classification{"not run"};
  double chatter_hz{0.0};
  std::string trip{"none"};  // the controller's
  double active_share{0.0};  // of the cut's ticks with the loop active
  [[nodiscard]] bool held() const { return complete && stable && trip == "none" && active_share >= 1.0; }
};

struct CellCheck {
  std::string cell{"the simulated plant in process"};
  std::vector<FrfCheck> frfs;
  std::string open_trip{"none"}, closed_trip{"none"};
  double closed_active_share{0.0};  // of the impact phase's ticks with the loop active at full gain
  unsigned long long closed_saturated_ticks{0};
  // In process: the damped cut's critical depth in time by bisection (the real Controller on the cell's
  // plant). Through the emulator: the depth its cut held at (cut_trials), 0 where it chattered.
  double time_domain_at_min_mm{0.0};    // at the promise's lobe-minimum speed
  double time_domain_at_speed_mm{0.0};  // at the job's speed
  std::vector<CutTrial> cut_trials;     // through the emulator: [0] the lobe minimum, [1] the job's speed
  double improvement_tolerance_points{5.0};
  double depth_tolerance{0.05};
  double wall_s{0.0};
  [[nodiscard]] bool improvement_ok() const;
  [[nodiscard]] bool depth_ok(const tune::Verification& promise) const;
  [[nodiscard]] std::string failure(const tune::Verification& promise) const;  // empty when both hold
  // One sentence: how the damped cut was checked on the cell and what it gave.
  [[nodiscard]] std::string cut_summary(const tune::Verification& promise) const;
};

// The measured improvement of every FRF of `tuned` (control off / on) beside the identified model's
// prediction. open / closed: the receptance measured for (excitation id, response id).
using ReceptanceOf = std::function<const analysis::FrfEstimate&(int excitation_id, int response_id)>;
[[nodiscard]] std::vector<FrfCheck> frf_checks(const config::Config& tuned, const ReceptanceOf& open,
                                               const ReceptanceOf& closed);

// cell: the cell's configuration (its plant is what runs); tuned: the identified, tuned configuration (its
// controller is run on the cell, its model makes the predictions); promise: tune::verify of `tuned`.
[[nodiscard]] CellCheck check_on_cell(const config::Config& cell, const config::Config& tuned,
                                      const config::MillingConfig& job, const tune::Verification& promise);

// The cell's configuration with the tuned configuration's controller section.
[[nodiscard]] config::Config with_controller_of(const config::Config& cell, const config::Config& tuned);

}  // namespace robodamp::commission
