// The commissioning measurement (robodamp measure, docs/identification.md section "Commissioning"):
// with control off and the amplifier enabled, a periodic chirp on the actuator, then hammer impacts at
// every configured location, on one timeline that the controller and the plant side (the simulated
// plant in process or the HIL emulator) both read from the configuration.
#pragma once

namespace robodamp::config {

struct CommissioningConfig {
  double settle_s{3.0};     // from the start of the run to the chirp: arming and the fade
  double chirp_f0_hz{2.0};  // each period sweeps f0 -> f1 linearly
  double chirp_f1_hz{100.0};
  double chirp_period_s{8.0};        // frequency resolution 1 / period
  int chirp_periods{4};              // the first is discarded (transient); the others are averaged
  double chirp_force_fraction{0.5};  // peak force predicted by the configured actuator / its limit
  double quiet_s{2.0};               // between the chirp and the first impact
  int impacts_per_location{6};
  double record_s{8.0};  // per impact (plus up to 1 s irregular gap)
  // The cell is at rest before the actuator excites it: the control accelerometer's RMS over the last
  // second before the chirp below this (a moving robot, a turning spindle or a cut: not ready).
  double rest_accel_rms_mps2{1.0};
};

}  // namespace robodamp::config
