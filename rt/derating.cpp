// Keeping damping when the cut chatters (docs/realtime_loop.md): the supervisor's derating. With the
// spindle turning, a growing command may be the loop's (the damper's fault: trip) or the cut's (a
// regenerative chatter the damper should keep damping). The loop's signals cannot tell the two apart at one
// frequency, so the supervisor asks the loop: it takes the gain away and watches. Growth that goes on without
// the gain is not the gain's (the process's: full gain again, and saturation derates instead of tripping);
// growth that decays was fed by the gain (inside a speed schedule's band: trip instability at once; elsewhere
// the gain is held lowered, and the same speed's gain feeding a growth again trips, latched). With the spindle
// stopped only the loop can feed a growth: it trips as it always did. RT-safe: arithmetic on members, no
// allocation.
#include <algorithm>
#include <cmath>

#include "rt/supervisor.hpp"

namespace robodamp::rt {

namespace {
// A probe's verdict. The growth was the gain's when a block's RMS falls under kProbeDecay of the block's before
// the probe (at once), or when, after probe_blocks blocks at the lowered gain, the straight line through the
// logarithms of the probe's blocks (least squares) ends under kProbeSettled of it; and the acceleration itself
// has not grown by more than kProbeAccelGrowth meanwhile (the chain does not pass every frequency: a chatter
// that moves to one it rejects must not look like a decay). A line rather than the last block: a chatter's
// limit cycle wanders by +/-20 % from block to block (measured at 1205 rpm, 20 mm), and one low block was
// read as a decay. While the line still falls (kProbeFalling) the probe goes on, up to kProbeLonger x
// probe_blocks (a lightly damped mode rings down slowly without the gain: swapped leads on the 9 Hz mode, 10 % a
// block); a line that does not fall is the process's. A loop 1.25 x over its stable gain decays to about 0.7
// in 0.3 s without the gain (the default preset's 23.5 Hz mode); a chatter grows on or holds.
constexpr double kProbeDecay = 0.5;
constexpr double kProbeSettled = 0.8;
constexpr double kProbeAccelGrowth = 1.1;
constexpr int kProbeLonger = 3;
constexpr double kProbeFalling = -0.03;  // ln RMS per block: a line falling by 3 % a block or more still falls
// A cut's entry (a block more than kImpulseJump x the one before) rings down for most of a second whatever the
// gain: a saturation within kEntrySettleS of it derates at once, and is probed only when it comes again after.
constexpr double kEntrySettleS = 1.0;
}  // namespace

// The least-squares line through (block, ln RMS) of the probe's blocks so far: its slope per block and its
// value at the newest block (as an RMS).
Supervisor::ProbeTrend Supervisor::ProbeFit::add(double rms) noexcept {
  const double x = n, y = std::log(std::max(rms, 1e-12));
  n += 1.0;
  sx += x;
  sy += y;
  sxx += x * x;
  sxy += x * y;
  const double den = n * sxx - sx * sx;
  const double slope = den > 0.0 ? (n * sxy - sx * sy) / den : 0.0;
  const double mean_x = sx / n, mean_y = sy / n;
  return {slope, std::exp(mean_y + slope * (x - mean_x))};
}

bool Supervisor::in_scheduled_band() const noexcept {
  const control::ControllerParams& p = controller_.params();
  return p.speed_scheduled() && p.speed_band_of(controller_.schedule_rpm()) < p.speed_band_count;
}

bool Supervisor::derating_on() const noexcept { return s_.limits.derate.enabled && controller_.schedule_rpm() > 0.0; }

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
  const DerateSettings& d = s_.limits.derate;
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
  const DerateSettings& d = s_.limits.derate;
  const double rpm = controller_.schedule_rpm();
  switch (growth_) {
    case Growth::kNone:
    case Growth::kGainFed:                            // held lowered, it grows again: probe again
      if (grown) start_probe(rms, accel_rms, false);  // where the instability rule trips with the spindle stopped
      break;
    case Growth::kProbe: {
      const ProbeTrend t = probe_fit_.add(rms);
      ++probe_blocks_;
      const bool judged = probe_blocks_ >= d.probe_blocks;
      const bool decayed = rms < kProbeDecay * probe_rms_ || (judged && t.end < kProbeSettled * probe_rms_);
      const bool end = judged && (t.slope >= kProbeFalling || probe_blocks_ >= kProbeLonger * d.probe_blocks);
      if (decayed && accel_rms <= kProbeAccelGrowth * probe_accel_rms_) {
        // it decays at the lowered gain: the gain fed it. Inside a speed schedule's band the tune verified
        // that the band's gain does not lower the cut's limit: a growth the gain feeds there is the loop's
        // own (or the cell is not the one commissioned), and switching the gain off cannot make the cut
        // worse: trip at once. A saturation's probe holds instead (a saturated actuator is past what the
        // band's linear check promises), as does any probe elsewhere (a gain fixed over all speeds may feed
        // the chatter of a speed it does not suit); the same speed's gain feeding a growth again trips.
        ++counters_.growth_gain_fed;
        log_event(EventKind::kGainFedGrowth, Trip::kInstability);
        if (gain_fed_rpm_ == rpm || (in_scheduled_band() && !probe_saturation_)) return true;
        gain_fed_rpm_ = rpm;
        growth_ = Growth::kGainFed;
        growth_run_ = 0;
        apply_derate(d.probe_ramp_s);
      } else if (end) {
        process_growth();                                  // it grew on, or held, without the gain: the process's
        if (probe_saturation_) (void)derate_saturation();  // an external force saturates the actuator (the first: 0.5)
      }
      break;
    }
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

// The gain taken away for probe_blocks blocks (or longer while the motion falls) to see whether the growth, or
// the saturation, goes on without it.
void Supervisor::start_probe(double rms, double accel_rms, bool saturation) noexcept {
  growth_ = Growth::kProbe;
  probe_saturation_ = saturation;
  probe_rms_ = rms;
  probe_accel_rms_ = accel_rms;
  probe_fit_ = {};
  probe_blocks_ = 0;
  apply_derate(s_.limits.derate.probe_ramp_s);
  ++counters_.derate_probes;
  log_event(EventKind::kProbe, saturation ? Trip::kSaturation : Trip::kInstability);
}

// The saturation duty over its limit; false when the trip stands. With the spindle stopped it trips (as it
// always did). With it turning, the first saturation since the last quiet spell (and over 1 s after a cut's
// entry) is probed as a growth is: the gain fed it (held lowered, even in a band: a saturated actuator is past
// the band's linear check) or an external force drives the actuator there (the process's: derated by
// saturation_factor).
// During a probe the controller commands nothing to saturate (the window starts afresh); once a growth or
// saturation was judged the process's, or the gain is held lowered, later saturations derate at once.
bool Supervisor::saturated_while_turning() noexcept {
  if (!derating_on()) return false;
  const bool settled = blocks_since_jump_ * block_len_ >= static_cast<std::uint64_t>(kEntrySettleS * s_.fs_hz);
  if (growth_ == Growth::kProbe || (growth_ == Growth::kNone && !process_ && settled)) {
    if (growth_ == Growth::kNone) start_probe(last_block_rms_, last_accel_rms_, true);
    std::fill(sat_window_.begin(), sat_window_.end(), std::uint8_t{0});
    sat_count_ = 0;
    return true;
  }
  return derate_saturation();
}

// The saturation duty over its limit with the spindle turning: the command derated by saturation_factor
// (the window starts afresh), down to min_factor; false when there is none left (the trip stands).
bool Supervisor::derate_saturation() noexcept {
  const DerateSettings& d = s_.limits.derate;
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
