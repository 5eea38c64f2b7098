// Tap tests from the integrator's modal kit, for commissioning a real cell (docs/identification.md,
// "Commissioning a real cell"): robodamp measures the actuator's location itself with its chirp, and the
// FRFs between the cell's locations (the tool tip above all) come from an impact test robodamp did not run.
// Read: universal files (dataset 58 FRFs per force, nodes = the configuration's location ids, in any unit
// the file names) and robodamp's FRF CSVs (frf_<response>_<excitation>.csv: f, Re, Im, coherence, m/N).
// Checked against the chirp before anything is tuned on them: the same modes in the actuator's own
// measurement, reciprocity where both directions were tapped, and the chirp explained by the identified
// actuator on the tapped structure. Off the real-time path.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "identify/commissioning.hpp"

namespace robodamp::identify {

struct TapTests {
  std::vector<IdentifiedFrf> frfs;  // one per pair of the configuration's locations (data only)
  // Pairs tapped both ways: (g <- h, h <- g), for the reciprocity check.
  std::vector<std::pair<IdentifiedFrf, IdentifiedFrf>> reciprocal;
  std::vector<std::string> files;
};

// Every pair of the configuration's locations must be in the files, once (either way round). Throws
// std::invalid_argument naming the file, the record and the pair (missing, twice, unreadable).
[[nodiscard]] TapTests read_tap_tests(const std::vector<std::string>& files, const MeasurementManifest& m,
                                      const config::Config& cfg);

// identify all's inputs on a real cell: the manifest and the chirp of a robodamp measure directory (the
// actuator's chirp, with or without impacts), the FRFs of the tap tests. Throws std::invalid_argument.
[[nodiscard]] CommissioningInputs inputs_with_tap_tests(const std::string& measurement_dir,
                                                        const std::vector<std::string>& tap_test_files, TapTests& taps);

struct TapModeCheck {
  double tap_hz{0.0}, tap_damping{0.0};
  std::optional<double> chirp_hz, chirp_damping;  // the nearest pole of the chirp's own fit
  double difference_pct{0.0};
  bool ok{false};
};

struct TapTestConsistency {
  std::vector<TapModeCheck> modes;  // the tapped path between the actuator and the sensor, in the band
  double tolerance_pct{0.0};        // a mode's frequency, tap test against chirp
  std::string chirp_fit;            // how the chirp was fitted, or why it could not be
  // The actuator's fit error: the force per volt the chirp implies through the tapped structure against
  // Eq. 3, weighed in the acceleration (RMS over the coherent band).
  double chirp_residual_pct{0.0};
  int residual_lines_left_out{0};  // lone lines ten times both neighbours' error (a periodic disturbance)
  double residual_limit_pct{10.0};
  struct Reciprocity {
    std::string pair;
    double difference_pct{0.0};  // RMS of |H_gh - H_hg| over RMS |H_gh|, coherent band
  };
  std::vector<Reciprocity> reciprocity;
  double reciprocity_limit_pct{20.0};
  [[nodiscard]] std::string failure() const;  // empty when the tap tests agree with the chirp
  [[nodiscard]] std::string summary() const;
};

// tolerance_pct: how far a tapped mode may sit from the chirp's (the fits' own spread allows about 1 %).
[[nodiscard]] TapTestConsistency check_tap_tests(const CommissioningInputs& in, const CommissioningResult& r,
                                                 const TapTests& taps, double tolerance_pct = 2.0);

}  // namespace robodamp::identify
