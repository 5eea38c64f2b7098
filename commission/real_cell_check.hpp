// Verification on a real cell (docs/identification.md, "Commissioning a real cell"): no hammer and no cut
// that robodamp can order, so the actuator is the shaker. Its chirp runs twice through the loop and the
// drivers, control off (the measure stage) and on with the tuned controller (the verify stage); against
// the chirp it injected, the loop's recording gives:
//   - the acceleration at the sensor per volt of chirp, off and on: the measured improvement of each
//     mode's peak at the actuator's location beside the tuned model's prediction (open / (1 + L));
//   - the loop gain, the classic injection measurement: the chirp e enters at the plant's input, the
//     command is u = e + c with c the controller's output, so L = -(c / e) / (u / e) with the analysis'
//     sign (closed loop 1 / (1 + L)); beside the tuned model's discrete loop, and the gain and phase
//     margins read from each over the chirp's band.
// Off the real-time path.
#pragma once

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "analysis/spectral.hpp"
#include "commission/measurement.hpp"
#include "config/config.hpp"
#include "identify/tap_tests.hpp"

namespace robodamp::commission {

// The chirp of a loop recording against its own reference (regenerated from the header on the loop's
// clock): acceleration, command and controller output per volt of chirp, averaged over the periods
// after the first.
struct ChirpLoopFrfs {
  analysis::FrfEstimate accel, command, controller;  // y / e, u / e, c / e (coherence against e)
  double fs_hz{0.0};
  double f0_hz{0.0}, f1_hz{0.0};
  int periods_averaged{0};
};
// Throws std::invalid_argument (no such file, no chirp, too short) or rt::RecordingError.
[[nodiscard]] ChirpLoopFrfs read_chirp_loop(const std::string& recording_path);

struct ModeCheckAtActuator {
  double freq_hz{0.0};                                                   // the identified mode's
  double measured_improvement_pct{0.0}, predicted_improvement_pct{0.0};  // open peak / closed peak - 1
};

struct LoopGainCheck {
  std::vector<double> f_hz;
  std::vector<std::complex<double>> measured, predicted;
  std::vector<double> coherence;  // the worse of the command's and the controller's
  // Over the compared points (coherence >= min_coherence and 0.1 <= |L predicted| <= 10, where the margins
  // live): the largest differences, and how many points.
  double max_error_db{0.0}, max_error_deg{0.0};
  double error_db_at_hz{0.0}, error_deg_at_hz{0.0};
  int compared_points{0};
  // Margins read from each curve over the chirp's band (nullopt: no crossover there).
  std::optional<double> measured_gm_db, predicted_gm_db, measured_pm_deg, predicted_pm_deg;
  double tolerance_db{1.0}, tolerance_deg{5.0};
  [[nodiscard]] bool holds() const;
};

struct RealCellCheck {
  std::string cell;  // what ran: the CAN bus or the HIL emulator told it is a real cell
  std::string open_trip{"none"}, closed_trip{"none"};
  std::string run_problem;  // the control-on chirp did not complete (refused, tripped, aborted)
  double closed_active_share{0.0};
  std::vector<double> f_hz, measured_open, measured_closed, predicted_open, predicted_closed;  // |y / e|, m/s^2 per V
  std::vector<ModeCheckAtActuator> modes;
  LoopGainCheck loop_gain;
  double improvement_tolerance_points{5.0};
  double wall_s{0.0};
  [[nodiscard]] std::string failure() const;  // empty when everything held
  // The log's lines (each mode, the loop gain), and the written configuration's comment lines.
  [[nodiscard]] std::vector<std::string> progress_lines() const;
  [[nodiscard]] std::string header_lines() const;
};

// off / on: the control-off and the control-on chirp's recordings; tuned: the identified, tuned
// configuration (its controller ran; its model predicts); modes_hz: the identified modes of the path
// between the actuator and the sensor.
[[nodiscard]] RealCellCheck check_real_cell(const ChirpLoopFrfs& off, const ChirpLoopFrfs& on,
                                            const config::Config& tuned, const std::vector<double>& modes_hz,
                                            double min_coherence = 0.9);

// Gain margin (dB, from -1 / L at the phase crossovers) and phase margin (deg, at the gain crossovers) of
// a loop sampled on a grid, by linear interpolation between points; nullopt where no crossover is.
[[nodiscard]] std::pair<std::optional<double>, std::optional<double>> margins_on_grid(
    const std::vector<double>& f_hz, const std::vector<std::complex<double>>& l);

// The verify stage on a real cell: the chirp with the tuned controller on the cell's wires (through the
// emulator, told it is real, when binary is not empty; else this process's loop and drivers), checked
// against the control-off chirp of measurement_dir. chirp_on: how that run went (refusals, trips).
struct RealCellRun {
  std::string cell_path, measurement_dir, work_dir;
  std::string binary;  // the emulator's executable; empty: the cell is hardware (or the simulated plant)
};
[[nodiscard]] RealCellCheck verify_on_real_cell(const config::Config& cell, const config::Config& tuned,
                                                const std::vector<double>& modes_hz, const RealCellRun& run,
                                                MeasureOutcome& chirp_on);

}  // namespace robodamp::commission
