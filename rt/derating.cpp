// Keeping damping when the cut chatters (docs/realtime_loop.md): the supervisor's derating. With the
// spindle turning, a growing command may be the loop's (the damper's fault: trip) or the cut's (a
// regenerative chatter the damper should keep damping). The loop's signals cannot tell the two apart at one
// frequency, so the supervisor asks the loop: it lowers the gain and watches. Growth that goes on at a
// quarter of the gain is not the gain's (the process's: full gain again, and saturation derates instead of
// tripping); growth that stops was fed by the gain (the gain is held lowered; the same speed's gain feeding a
// growth again trips instability, latched). With the spindle stopped only the loop can feed a growth: it trips
// as it always did. RT-safe: arithmetic on members, no allocation.
#include <algorithm>

#include "rt/supervisor.hpp"

namespace robodamp::rt {

namespace {
// A probe's verdict: the growth was the gain's when a block's RMS falls under kProbeDecay of the block's before
// the probe (at once), or under kProbeSettled of it at the probe's end (probe_blocks blocks at the lowered gain),
// and the acceleration itself has not grown by more than kProbeAccelGrowth meanwhile (the chain does not pass
// every frequency: a chatter that moves to one it rejects must not look like a decay). A loop 1.25 x over its
// stable gain decays to about 0.7 in 0.3 s without the gain (the default preset's 23.5 Hz mode); a chatter that
// grows on or holds its limit cycle stays above.
constexpr double kProbeDecay = 0.5;
constexpr double kProbeSettled = 0.8;
constexpr double kProbeAccelGrowth = 1.1;
}  // namespace

bool Supervisor::derating_on() const noexcept {
  return s_.limits.derate.enabled && controller_.schedule_rpm() > 0.0;
}

// What the growth detector follows: with the spindle stopped the controller's output (as it always did); with
// it turning what the controller would command at the K it is heading for, without derating or limits: the
// structure's motion through the chain, so that neither lowering the gain, nor a limit, nor a gain ramp (a
// band's K, a hand-over's fade-in, the restore) starts, ends or hides a growth.
double Supervisor::growth_signal_v(double controller_v) const noexcept {
  if (!derating_on()) return controller_v;
  const control::ControllerParams& p = controller_.params();
  return p.polarity * controller_.target_gain_ns_per_m() * controller_.filtered_mps() / p.actuator_constant_n_per_v;
}

void Supervisor::apply_derate(double ramp_s) noexcept {
  const config::DerateConfig& d = s_.limits.derate;
  const double f = growth_ == Growth::kProbe ? d.probe_factor : growth_ == Growth::kGainFed ? d.hold_factor : 1.0;
  controller_.set_derate(f * saturation_derate_, ramp_s);
}

void Supervisor::reset_derate() noexcept {
  growth_ = Growth::kNone;
  process_ = false;
  saturation_derate_ = 1.0;
  quiet_blocks_ = 0;
  gain_fed_rpm_ = -1.0;
  controller_.set_derate(1.0, 0.0);
}

// The growth is the process's: full gain again (but for the saturation's derating); the next probe after a new
// run that would trip.
void Supervisor::process_growth() noexcept {
  growth_ = Growth::kNone;
  process_ = true;
  gain_fed_rpm_ = -1.0;
  growth_run_ = 0;
  apply_derate(s_.limits.derate.probe_ramp_s);
  ++counters_.growth_process;
  log_event(EventKind::kProcessGrowth, Trip::kInstability);
}

// One instability block with the spindle turning: grown is the detector's trip verdict without derating.
bool Supervisor::judge_growth(double rms, double accel_rms, bool grown) noexcept {
  const config::DerateConfig& d = s_.limits.derate;
  const double rpm = controller_.schedule_rpm();
  switch (growth_) {
    case Growth::kNone:
    case Growth::kGainFed:  // held lowered, it grows again: probe again
      if (grown) {  // where the instability rule trips with the spindle stopped
        growth_ = Growth::kProbe;
        probe_rms_ = rms;
        probe_accel_rms_ = accel_rms;
        probe_blocks_ = 0;
        apply_derate(d.probe_ramp_s);
        ++counters_.derate_probes;
        log_event(EventKind::kProbe, Trip::kInstability);
      }
      break;
    case Growth::kProbe:
      ++probe_blocks_;
      if (const bool end = probe_blocks_ >= d.probe_blocks;
          rms < (end ? kProbeSettled : kProbeDecay) * probe_rms_ && accel_rms <= kProbeAccelGrowth * probe_accel_rms_) {
        // it decays at the lowered gain: the gain fed it
        if (gain_fed_rpm_ == rpm) return true;  // at this speed for the second time: the loop's own, trip
        gain_fed_rpm_ = rpm;
        growth_ = Growth::kGainFed;
        growth_run_ = 0;
        apply_derate(d.probe_ramp_s);
        ++counters_.growth_gain_fed;
        log_event(EventKind::kGainFedGrowth, Trip::kInstability);
      } else if (end) {
        process_growth();  // it grew on, or held, without the gain: the process's
      }
      break;
  }
  return false;
}

// Each block: derated, or after a process's growth, and quiet for quiet_s (no growth over two blocks, the
// saturation duty under a quarter of its limit): back to full gain over restore_s.
void Supervisor::restore_when_quiet() noexcept {
  if (growth_ == Growth::kProbe || (growth_ == Growth::kNone && !process_ && saturation_derate_ >= 1.0)) {
    quiet_blocks_ = 0;
    return;
  }
  const bool quiet = growth_run_ < 2 && 4 * sat_count_ <= sat_threshold_;
  quiet_blocks_ = quiet ? quiet_blocks_ + 1 : 0;
  if (static_cast<double>(quiet_blocks_ * block_len_) < s_.limits.derate.quiet_s * s_.fs_hz) return;
  const bool was_derated = controller_.derate_target() < 1.0;
  growth_ = Growth::kNone;
  process_ = false;
  saturation_derate_ = 1.0;
  quiet_blocks_ = 0;
  if (!was_derated) return;
  controller_.set_derate(1.0, s_.limits.derate.restore_s);
  ++counters_.derate_restores;
  log_event(EventKind::kRestored, Trip::kNone);
}

// The saturation duty over its limit with the spindle turning: the command derated by saturation_factor
// (the window starts afresh), down to min_factor; false when there is none left (the trip stands).
bool Supervisor::derate_saturation() noexcept {
  const config::DerateConfig& d = s_.limits.derate;
  if (!derating_on() || saturation_derate_ * d.saturation_factor < d.min_factor) return false;
  saturation_derate_ *= d.saturation_factor;
  apply_derate(d.probe_ramp_s);
  std::fill(sat_window_.begin(), sat_window_.end(), std::uint8_t{0});
  sat_count_ = 0;
  ++counters_.saturation_derates;
  log_event(EventKind::kSaturationDerate, Trip::kSaturation);
  return true;
}

}  // namespace robodamp::rt
