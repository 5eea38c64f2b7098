#include "runtime/monitor_view.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>

#include "config/pose_schedule_config.hpp"
#include "dds/latest_sample.hpp"
#include "dds/participant.hpp"
#include "rt/signals.hpp"
#include "rt/supervisor.hpp"
#include "runtime/advice_view.hpp"

namespace robodamp::runtime {

namespace {

std::string mm(double v) {
  char b[32];
  if (std::isinf(v)) return "no lobe";
  std::snprintf(b, sizeof b, "%.3f mm", v);
  return b;
}

}  // namespace

std::string monitor_status_text(const msg::Telemetry& t, std::uint64_t nt, const msg::Status& s, std::uint64_t ns) {
  char b[1200];
  if (ns == 0) {  // the telemetry alone: the status's numbers (limit, set, timing, damping) are not known yet
    std::snprintf(b, sizeof b,
                  "robodamp monitor  cell %s  t = %.2f s  (no status yet)\n"
                  "  state      %-10s trip %s\n"
                  "  vibration  %.5f m/s^2 RMS (last %.5f m/s^2), velocity estimate %.3g m/s\n"
                  "  command    %+.4f V (peak %.4f V), K = %.0f N s/m; limit, parameter set, timing and damping "
                  "come with the first status\n"
                  "  saturation %.1f %% of the last window\n"
                  "  samples    %llu telemetry, 0 status; parameter writes -\n",
                  t.cell().c_str(), t.time_s(), nt ? rt::to_string(static_cast<rt::State>(t.state())) : "-",
                  nt ? rt::to_string(static_cast<rt::Trip>(t.trip())) : "-", t.accel_rms_mps2(), t.accel_mps2(),
                  t.filtered_mps(), t.command_v(), t.command_peak_v(), t.gain_ns_per_m(),
                  100.0 * t.saturated_fraction(), static_cast<unsigned long long>(nt));
    return b;
  }
  const char* state = ns ? s.state().c_str() : nt ? rt::to_string(static_cast<rt::State>(t.state())) : "-";
  const char* trip = ns ? s.trip().c_str() : nt ? rt::to_string(static_cast<rt::Trip>(t.trip())) : "-";
  std::snprintf(
      b, sizeof b,
      "robodamp monitor  cell %s  t = %.2f s  (%s)\n"
      "  state      %-10s trip %s\n"
      "  vibration  %.5f m/s^2 RMS (last %.5f m/s^2), velocity estimate %.3g m/s\n"
      "  command    %+.4f V (peak %.4f V), K = %.0f N s/m (limit %.0f), parameter set %u\n"
      "  saturation %.1f %% of the last window, %llu ticks in all\n"
      "  timing     wake-up p50 %.0f us, p99 %.0f us, max %.1f us; compute mean %.2f us, max %.1f us\n"
      "             ticks %llu, missed %llu, overruns %llu, stale %llu, ring drops %llu\n"
      "  damping    %.3f %% of the time asked (%.3f %% derated%s); %u trips, %u back at full gain; last trip %s\n"
      "  samples    %llu telemetry, %llu status; parameter writes %s\n",
      ns ? s.cell().c_str() : t.cell().c_str(), nt ? t.time_s() : s.time_s(),
      ns ? s.backend().c_str() : "no status yet", state, trip, t.accel_rms_mps2(), t.accel_mps2(), t.filtered_mps(),
      t.command_v(), t.command_peak_v(), nt ? t.gain_ns_per_m() : s.gain_ns_per_m(), s.max_gain_ns_per_m(),
      s.parameter_set(), 100.0 * t.saturated_fraction(), static_cast<unsigned long long>(s.saturated_ticks()),
      s.wake_p50_us(), s.wake_p99_us(), s.wake_max_us(), s.compute_mean_us(), s.compute_max_us(),
      static_cast<unsigned long long>(s.ticks()), static_cast<unsigned long long>(s.missed_ticks()),
      static_cast<unsigned long long>(s.overruns()), static_cast<unsigned long long>(s.stale_ticks()),
      static_cast<unsigned long long>(s.ring_drops()), s.availability_pct(), s.derated_pct(),
      s.derated() ? ", DERATED now" : "", s.trips(), s.back_at_full_gain(),
      s.last_trip_s() >= 0.0 ? (std::to_string(s.last_trip_s()) + " s").c_str() : "none",
      static_cast<unsigned long long>(nt), static_cast<unsigned long long>(ns),
      ns ? (s.parameter_writes() ? "on" : "off") : "-");
  return b;
}

// The machining lines (spindle.job): speed, depth, limits, chatter indicator.
std::string monitor_machining_text(const msg::Machining& m) {
  char b[1200];
  std::string limits = "computing";
  if (m.spindle_rpm() <= 0.0)
    limits = "spindle stopped";
  else if (m.limits_ready())
    limits = "open " + mm(m.open_limit_mm()) + " (SDM), damped " + mm(m.damped_limit_mm()) + " (" + m.limit_method() +
             "); now " + mm(m.limit_mm()) + (m.loop_active() ? " (damper active)" : " (damper off)") +
             (m.depth_warning()
                  ? (m.depth_measured() ? "  WARNING: depth above the limit"
                     : m.cutting() == dds::kNotCutting
                         ? "  the job's planned depth is above the limit here (not cutting now)"
                         : "  WARNING: the job's planned depth is above the limit (the robot reports no depth)")
                  : "  depth within");
  if (m.spindle_rpm() > 0.0 && !m.limits_pose_deg().empty()) {
    limits += "\n             at the robot's pose " + config::describe_pose(m.limits_pose_deg()) +
              (m.limits_ready() ? "" : " (recomputing: the robot moved)");
    if (m.mode_spread_pct() >= 0.0) {
      char spread[160];
      std::snprintf(spread, sizeof spread, "; its modes +-%.1f %% (one sigma), %.0f deg from the nearest measured pose",
                    m.mode_spread_pct(), m.nearest_measured_deg());
      limits += spread;
    }
  }
  std::string indicator = "-";
  if (m.indicator_valid()) {
    char c[200];
    std::snprintf(c, sizeof c, "once-per-rev %.2f, non-harmonic %.0f %% (strongest %.1f Hz): %s",
                  m.once_per_rev_ratio(), 100.0 * m.nonharmonic_share(), m.chatter_hz(),
                  m.chatter() ? "CHATTER" : "no chatter");
    indicator = c;
  } else if (m.spindle_rpm() > 0.0) {
    indicator = "collecting revolutions";
  }
  // Not cutting: said first, the indicator's figures after it (an engineer still reads them).
  if (m.cutting() == dds::kNotCutting)
    indicator = "not cutting (" + m.cutting_reason() + ")" + (m.indicator_valid() ? "; " + indicator : "");
  std::snprintf(b, sizeof b,
                "  spindle    %.0f rpm (tooth passing %.1f Hz), depth %.3f mm%s\n"
                "  stability  %s\n"
                "  chatter    %s\n",
                m.spindle_rpm(), m.tooth_passing_hz(), m.depth_mm(),
                m.depth_measured() ? " (the robot's)" : " (the job's plan)", limits.c_str(), indicator.c_str());
  return b;
}

// The advice line: the topic's fields as the run summary shows them.
std::string monitor_advice_text(const msg::Advice& m) {
  dds::AdviceSample a;
  a.seq = m.seq();
  a.time_s = m.time_s();
  a.trigger = m.trigger();
  a.spindle_rpm = m.spindle_rpm();
  a.depth_mm = m.depth_mm();
  a.damped = m.damped();
  a.chatter_hz = m.chatter_hz();
  a.limit_now_mm = m.limit_now_mm();
  a.method = m.method();
  a.found = m.found();
  a.option_rpm = m.option_rpm();
  a.option_limit_mm = m.option_limit_mm();
  a.option_limit_mm.resize(a.option_rpm.size(), 0.0);
  a.reason = m.reason();
  a.pose_deg = m.pose_deg();
  a.poses_ahead = m.poses_ahead();
  a.limiting_pose_deg = m.limiting_pose_deg();
  a.status = m.status();
  a.status_reason = m.status_reason();
  return advice_text(a);
}

namespace {

using Clock = std::chrono::steady_clock;

// Nothing new for this long: the monitor says the loop is out of contact (the dashboard's stale_after_s is 2 s;
// the status alone comes at dds.status_rate_hz, 5 Hz by default).
constexpr double kNoContactS = 3.0;

}  // namespace

int watch_cell(const dds::ClientOptions& o, std::ostream& out, std::ostream& err) {
  rt::install_shutdown_handlers();
  auto cell = std::make_shared<std::string>(o.cell);  // empty: the first cell heard
  dds::Latest<msg::Telemetry> telemetry(cell);        // before the participant: it outlives the readers that call it
  dds::Latest<msg::Status> status(cell);
  dds::Latest<msg::Machining> machining(cell);
  dds::Latest<msg::Advice> advice(cell);
  dds::Participant p(o.domain_id, o.transport, "robodamp monitor", o.security);
  p.reader(dds::TopicKind::kTelemetry, &telemetry);
  p.reader(dds::TopicKind::kStatus, &status);
  p.reader(dds::TopicKind::kMachining, &machining);
  p.reader(dds::TopicKind::kAdvice, &advice);
  const bool tty = isatty(STDOUT_FILENO) != 0;  // the terminal redrawn in place
  err << "robodamp monitor: domain " << o.domain_id << " (" << config::to_string(o.transport)
      << "), waiting for a loop; Ctrl-C ends\n";
  const auto end = Clock::now() + std::chrono::duration<double>(o.duration_s);
  std::uint64_t shown = 0;
  auto heard = Clock::now();
  bool silent = false;  // said "no contact" and heard nothing since
  while (rt::shutdown_signal().load() == 0 && (o.duration_s <= 0.0 || Clock::now() < end)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const auto [t, nt] = telemetry.get();
    const auto [s, ns] = status.get();
    const auto [m, nm] = machining.get();
    const auto [a, na] = advice.get();
    if (nt + ns + nm + na == shown) {
      // A loop that stops publishing (ended, crashed, the link down) is said, not shown frozen.
      const double quiet_s = std::chrono::duration<double>(Clock::now() - heard).count();
      if (shown > 0 && !silent && quiet_s >= kNoContactS) {
        silent = true;
        out << "robodamp monitor: NO CONTACT: nothing from " << (ns ? s.cell().c_str() : t.cell().c_str()) << " for "
            << static_cast<int>(quiet_s) << " s: the loop stopped or the link is down (last seen: state "
            << (nt ? rt::to_string(static_cast<rt::State>(t.state())) : s.state().c_str()) << " at loop time "
            << (nt ? t.time_s() : s.time_s()) << " s); the view above is old\n"
            << std::flush;
      }
      continue;
    }
    if (silent) out << "robodamp monitor: contact again\n";
    silent = false;
    heard = Clock::now();
    shown = nt + ns + nm + na;
    if (tty) out << "\x1b[H\x1b[2J";  // redraw in place
    out << runtime::monitor_status_text(t, nt, s, ns) << (nm ? runtime::monitor_machining_text(m) : "")
        << (na ? runtime::monitor_advice_text(a) : "") << (tty ? "" : "\n") << std::flush;
  }
  return shown > 0 ? 0 : 1;
}

}  // namespace robodamp::runtime
