#include "runtime/run_summary_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "runtime/advice_view.hpp"
#include "config/pose_schedule_config.hpp"
#include "fields/json.hpp"

namespace robodamp::runtime {

namespace {

// The hardware devices' counters (CAN, Modbus, DDS), a line each, from their field lists.
[[nodiscard]] std::string devices_text(const runtime::RunSummary& s) {
  std::string out;
  auto line = [&out](const char* name, const std::string& counters) {
    out += "  " + std::string(name) + ": " + counters + "\n";
  };
  if (s.can) line("CAN", fields::text(*s.can));
  if (s.modbus) line("Modbus", fields::text(*s.modbus));
  if (s.joint_states) line("DDS joint states", fields::text(*s.joint_states));
  if (s.path_ahead) line("DDS path ahead", fields::text(*s.path_ahead));
  if (s.dds) line("DDS", fields::text(*s.dds));
  return out;
}

}  // namespace

// long: one entry per field of the run summary (the documented JSON shape)
nlohmann::json summary_json(const runtime::RunSummary& s) {
  using nlohmann::json;
  auto hist = [](const rt::TimingHistogram& h) {
    return json{{"count", h.count()},
                {"p50_us", h.percentile_us(0.5)},
                {"p99_us", h.percentile_us(0.99)},
                {"p999_us", h.percentile_us(0.999)},
                {"max_us", h.max_us()},
                {"mean_us", h.mean_us()}};
  };
  json supervisor = fields::to_json(s.supervisor);
  supervisor["active_parameter_set"] = s.active_parameter_set;
  const auto ticks = static_cast<double>(std::max<std::uint64_t>(1, s.loop.ticks_run + s.loop.missed_ticks));
  json j = {{"config", s.config},
            {"clock", s.clock},
            {"rate_hz", s.rate_hz},
            {"duration_s", s.duration_s},
            {"elapsed_s", s.loop.elapsed_s},
            {"final_state", s.final_state},
            {"trip", s.trip},
            {"trip_description", s.trip_description},
            {"analysis_stable", s.analysis_stable},
            {"max_stable_gain_ns_per_m", s.max_stable_gain_ns_per_m},
            {"ticks_run", s.loop.ticks_run},
            {"missed_ticks", s.loop.missed_ticks},
            {"overruns", s.loop.overruns},
            {"overrun_pct", 100.0 * static_cast<double>(s.loop.overruns) / ticks},
            {"wake_latency", hist(s.loop.wake_latency)},
            {"compute", hist(s.loop.compute)},
            {"telemetry",
             {{"frames", s.telemetry_frames}, {"ring_drops", s.loop.ring_drops}, {"ring_waits", s.loop.ring_waits}}},
            {"recording", {{"path", s.record_path}, {"frames", s.recorded_frames}, {"write_errors", s.record_errors}}},
            {"supervisor", supervisor},
            {"realtime",
             {{"memory_locked", s.realtime.memory_locked},
              {"sched_fifo", s.realtime.fifo},
              {"priority", s.realtime.priority},
              {"affinity", s.realtime.affinity},
              {"timer_slack_1ns", s.realtime.timer_slack},
              {"cpu_dma_latency_held", s.realtime.dma_latency_held},
              {"warnings", s.realtime.warnings}}},
            {"sensor_rms_mps2", s.sensor_rms_mps2},
            {"peak_command_v", s.peak_command_v},
            {"spindle", {{"rpm", s.spindle_rpm}, {"notch_centre_hz", s.notch_centre_hz}}},
            {"gain_ns_per_m", s.gain_ns_per_m}};
  if (s.speed_bands > 0)
    j["speed_schedule"] = {{"bands", s.speed_bands},
                           {"band", s.speed_band ? json(*s.speed_band) : json(nullptr)},
                           {"handovers", s.supervisor.speed_handovers},
                           {"handovers_refused", s.supervisor.speed_handovers_refused}};
  j["backend"] = s.backend;
  j["events"] = json::array();
  for (const auto& e : s.events)
    j["events"].push_back({{"time_s", e.time_s}, {"event", rt::to_string(e.kind)}, {"trip", rt::to_string(e.trip)}});
  j["events_total"] = s.events_total;
  j["arming"] = {{"enabled", s.arming.enabled},
                 {"outcome", runtime::to_string(s.arming.outcome)},
                 {"attempts", s.arming.attempts},
                 {"last_refusal", rt::to_string(s.arming.last_refusal)},
                 {"deadline_s", s.arming.deadline_s}};
  auto t = [](double v) { return v >= 0.0 ? json(v) : json(nullptr); };
  j["trip_timing"] = {
      {"last_fresh_s", t(s.trip_timing.last_fresh_s)},
      {"trip_s", t(s.trip_timing.trip_s)},
      {"safe_s", t(s.trip_timing.safe_s)},
      {"ticks_to_safe", s.trip_timing.ticks_to_safe >= 0 ? json(s.trip_timing.ticks_to_safe) : json(nullptr)}};
  {
    const auto& a = s.availability;
    json trip_list = json::array();
    for (const auto& tr : a.trips)
      trip_list.push_back({{"trip", tr.trip},
                           {"trip_s", tr.trip_s},
                           {"safe_s", t(tr.safe_s)},
                           {"rearmed_s", t(tr.rearmed_s)},
                           {"full_gain_again_s", t(tr.full_gain_again_s)},
                           {"safe_after_s", tr.safe_s >= 0.0 ? json(tr.safe_s - tr.trip_s) : json(nullptr)},
                           {"rearmed_after_s", tr.rearmed_s >= 0.0 ? json(tr.rearmed_s - tr.trip_s) : json(nullptr)},
                           {"full_gain_after_s",
                            tr.full_gain_again_s >= 0.0 ? json(tr.full_gain_again_s - tr.trip_s) : json(nullptr)}});
    j["availability"] = {{"asked_s", a.asked_s},
                         {"active_full_gain_s", a.active_s},
                         {"missed_ticks_while_active_s", a.missed_while_active_s},
                         {"sensor_held_s", a.sensor_held_s},
                         {"derated_s", a.derated_s},
                         {"share", a.share()},
                         {"first_full_gain_s", t(a.first_full_gain_s)},
                         {"trips_total", a.trips_total},
                         {"trips", trip_list}};
  }
  if (s.can) j["can"] = fields::to_json(*s.can);
  if (s.dds) j["dds"] = fields::to_json(*s.dds);
  if (s.machining) {
    const auto& m = *s.machining;
    auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    j["machining"] = {{"spindle_rpm", m.spindle_rpm},
                      {"depth_mm", m.depth_mm},
                      {"limits_ready", m.limits_ready},
                      {"open_limit_mm", finite(m.open_limit_mm)},
                      {"damped_limit_mm", finite(m.damped_limit_mm)},
                      {"limit_method", m.limit_method},
                      {"loop_active", m.loop_active},
                      {"limit_mm", finite(m.limit_mm)},
                      {"depth_warning", m.depth_warning},
                      {"depth_measured", m.depth_measured},
                      {"indicator_valid", m.indicator_valid},
                      {"once_per_rev_ratio", m.once_per_rev_ratio},
                      {"nonharmonic_share", m.nonharmonic_share},
                      {"chatter_hz", m.chatter_hz},
                      {"cutting", dds::cutting_name(m.cutting)},
                      {"cutting_reason", m.cutting_reason},
                      {"chatter", m.chatter}};
    if (!m.pose_deg.empty() || !m.limits_pose_deg.empty())
      j["machining"]["pose_deg"] = m.pose_deg, j["machining"]["limits_pose_deg"] = m.limits_pose_deg;
    if (m.mode_spread_pct >= 0.0)
      j["machining"]["mode_spread_pct"] = m.mode_spread_pct,
      j["machining"]["nearest_measured_deg"] = m.nearest_measured_deg;
  }
  if (!s.limits_trail.empty()) {
    json trail = json::array();
    for (const auto& r : s.limits_trail)
      trail.push_back(
          {{"time_s", r.time_s},
           {"pose_deg", r.limits.pose_deg},
           {"spindle_rpm", r.limits.rpm},
           {"parameter_set", r.set},
           {"gain_ns_per_m", r.gain_ns_per_m},
           {"open_limit_mm", std::isfinite(r.limits.open_mm) ? json(r.limits.open_mm) : json(nullptr)},
           {"damped_limit_mm", std::isfinite(r.limits.damped_mm) ? json(r.limits.damped_mm) : json(nullptr)},
           {"method", r.limits.method},
           {"problem", r.limits.problem},
           {"loop_model_open_limit_mm",
            std::isfinite(r.limits.loop_open_mm) ? json(r.limits.loop_open_mm) : json(nullptr)},
           {"loop_model_verified", r.limits.loop_model_verified}});
    j["limits_along_path"] = trail;
  }
  if (s.advice) j["advice"] = advice_json(runtime::to_sample(*s.advice));
  if (s.modbus) j["modbus"] = fields::to_json(*s.modbus);
  if (s.joint_states) j["joint_states"] = fields::to_json(*s.joint_states);
  if (s.path_ahead) j["path_ahead"] = fields::to_json(*s.path_ahead);
  return j;
}

// long: one line per field of the run summary, in the order an operator reads them
std::string summary_text(const runtime::RunSummary& s) {
  std::ostringstream os;
  char b[512];
  const auto& st = s.loop;
  const double all = static_cast<double>(std::max<std::uint64_t>(1, st.ticks_run + st.missed_ticks));
  std::snprintf(b, sizeof b, "robodamp run: %s, %s, %s clock, %.0f Hz, %.3f s (%.3f s elapsed)\n", s.config.c_str(),
                s.backend.c_str(), s.clock.c_str(), s.rate_hz, s.duration_s, st.elapsed_s);
  os << b;
  if (s.clock == "wall") {
    os << "  real time: " << (s.realtime.fifo ? "SCHED_FIFO " + std::to_string(s.realtime.priority) : "SCHED_OTHER")
       << (s.realtime.memory_locked ? ", memory locked" : "")
       << (s.realtime.dma_latency_held ? ", cpu_dma_latency 0" : "")
       << (s.realtime.timer_slack ? ", timer slack 1 ns" : "") << (s.realtime.affinity ? ", pinned" : "") << '\n';
  }
  os << "  state: " << s.final_state;
  if (s.trip != "none") os << "  (tripped: " << s.trip << " - " << s.trip_description << ")";
  os << '\n';
  if (s.arming.enabled) {
    os << "  arming: " << runtime::to_string(s.arming.outcome) << " after " << s.arming.attempts << " attempt(s)";
    if (s.arming.last_refusal != rt::ArmRefusal::kNone)
      os << "; last refusal: " << rt::to_string(s.arming.last_refusal);
    os << '\n';
  }
  std::snprintf(b, sizeof b, "  ticks %llu, missed %llu, overruns %llu (%.4f %%)\n",
                static_cast<unsigned long long>(st.ticks_run), static_cast<unsigned long long>(st.missed_ticks),
                static_cast<unsigned long long>(st.overruns), 100.0 * static_cast<double>(st.overruns) / all);
  os << b;
  if (s.clock == "wall") {
    const auto& h = st.wake_latency;
    std::snprintf(b, sizeof b, "  wake-up latency: p50 %.0f us, p99 %.0f us, p99.9 %.0f us, max %.1f us\n",
                  h.percentile_us(0.5), h.percentile_us(0.99), h.percentile_us(0.999), h.max_us());
    os << b;
  }
  std::snprintf(b, sizeof b, "  compute per tick: mean %.2f us, p99 %.0f us, max %.1f us\n", st.compute.mean_us(),
                st.compute.percentile_us(0.99), st.compute.max_us());
  os << b;
  std::string trips;
  for (std::size_t i = 1; i < rt::kTripCount; ++i)
    if (s.supervisor.trips[i] > 0)
      trips += std::string(trips.empty() ? "" : ", ") + rt::to_string(static_cast<rt::Trip>(i)) + " " +
               std::to_string(s.supervisor.trips[i]);
  std::snprintf(
      b, sizeof b,
      "  supervisor: stale %llu, invalid %llu, saturated %llu ticks, arm refused %llu, gain refused %llu; trips: %s\n",
      static_cast<unsigned long long>(s.supervisor.stale_ticks),
      static_cast<unsigned long long>(s.supervisor.invalid_samples),
      static_cast<unsigned long long>(s.supervisor.saturated_ticks),
      static_cast<unsigned long long>(s.supervisor.arm_refused),
      static_cast<unsigned long long>(s.supervisor.gain_refused), trips.empty() ? "none" : trips.c_str());
  os << b;
  if (const auto& v = s.supervisor; v.derate_probes + v.saturation_derates > 0) {
    std::snprintf(
        b, sizeof b,
        "  derating (the spindle turning): %llu growth probes (%llu the process's: damping at full gain, %llu "
        "fed by the gain: held lowered), %llu saturation derates, %llu back to full gain; %llu ticks derated\n",
        static_cast<unsigned long long>(v.derate_probes), static_cast<unsigned long long>(v.growth_process),
        static_cast<unsigned long long>(v.growth_gain_fed), static_cast<unsigned long long>(v.saturation_derates),
        static_cast<unsigned long long>(v.derate_restores), static_cast<unsigned long long>(v.derated_ticks));
    os << b;
  }
  if (s.events_total > 0) {
    std::snprintf(b, sizeof b, "  recovery: %llu recovered, %llu latched by the budget, %llu by the probation; events:",
                  static_cast<unsigned long long>(s.supervisor.recoveries),
                  static_cast<unsigned long long>(s.supervisor.budget_latches),
                  static_cast<unsigned long long>(s.supervisor.probation_latches));
    os << b;
    for (const auto& e : s.events) {
      std::snprintf(b, sizeof b, " %.3f s %s %s;", e.time_s, rt::to_string(e.kind), rt::to_string(e.trip));
      os << b;
    }
    if (s.events_total > s.events.size()) os << " (" << s.events_total - s.events.size() << " more)";
    os << '\n';
  }
  std::snprintf(b, sizeof b, "  vibration at the sensor: %.4f m/s^2 RMS; peak command %.3f V; K_max %.0f N s/m\n",
                s.sensor_rms_mps2, s.peak_command_v, s.max_stable_gain_ns_per_m);
  os << b;
  std::snprintf(b, sizeof b, "  telemetry: %llu frames, %llu dropped",
                static_cast<unsigned long long>(s.telemetry_frames), static_cast<unsigned long long>(st.ring_drops));
  os << b;
  if (!s.record_path.empty())
    os << "; recorded " << s.recorded_frames << " frames to " << s.record_path
       << (s.record_errors ? " (" + std::to_string(s.record_errors) + " write errors)" : "");
  os << '\n';
  os << devices_text(s);
  if (s.supervisor.overrun_runs_ridden > 0) {
    std::snprintf(
        b, sizeof b,
        "  overruns: %llu runs of supervision.overrun_cycles or more ridden through within the delay margin\n",
        static_cast<unsigned long long>(s.supervisor.overrun_runs_ridden));
    os << b;
  }
  if (s.supervisor.sensor_holds > 0) {
    std::snprintf(
        b, sizeof b,
        "  stale or invalid samples while driving: %llu runs, %llu ticks (the longest %llu), ridden through with "
        "the controller's command zero\n",
        static_cast<unsigned long long>(s.supervisor.sensor_holds),
        static_cast<unsigned long long>(s.supervisor.sensor_hold_ticks),
        static_cast<unsigned long long>(s.supervisor.longest_sensor_hold_ticks));
    os << b;
  }
  if (s.availability.first_full_gain_s >= 0.0) {
    const auto& a = s.availability;
    std::size_t rearmed = 0;
    double worst = 0.0;
    for (const auto& tr : a.trips)
      if (tr.full_gain_again_s >= 0.0) ++rearmed, worst = std::max(worst, tr.full_gain_again_s - tr.trip_s);
    std::snprintf(b, sizeof b,
                  "  availability: damping (active past the fade-in) %.4f %% of the %.1f s asked (from %.3f s; %.4f %% "
                  "of it missed ticks, the "
                  "command held; %.4f %% derated; %.4f %% more on stale samples, not counted); %llu trips, %zu back at "
                  "full gain (the slowest after %.2f s)\n",
                  100.0 * a.share(), a.asked_s, a.first_full_gain_s,
                  a.asked_s > 0.0 ? 100.0 * a.missed_while_active_s / a.asked_s : 0.0,
                  a.asked_s > 0.0 ? 100.0 * a.derated_s / a.asked_s : 0.0,
                  a.asked_s > 0.0 ? 100.0 * a.sensor_held_s / a.asked_s : 0.0,
                  static_cast<unsigned long long>(a.trips_total), rearmed, worst);
    os << b;
  }
  if (s.trip_timing.trip_s >= 0.0) {
    std::snprintf(b, sizeof b, "  trip at %.4f s (last fresh sample %.4f s), safe at %.4f s (%lld ticks after it)\n",
                  s.trip_timing.trip_s, s.trip_timing.last_fresh_s, s.trip_timing.safe_s,
                  static_cast<long long>(s.trip_timing.ticks_to_safe));
    os << b;
  }
  if (s.speed_bands > 0) {
    std::snprintf(
        b, sizeof b,
        "  speed schedule: %zu bands; at the end %s, set %zu at K %.0f N s/m; %llu hand-overs as the "
        "spindle moved%s\n",
        s.speed_bands, s.speed_band ? ("band " + std::to_string(*s.speed_band)).c_str() : "outside every band",
        s.active_parameter_set, s.gain_ns_per_m, static_cast<unsigned long long>(s.supervisor.speed_handovers),
        s.supervisor.speed_handovers_refused ? " (some REFUSED: K held at 0 there)" : "");
    os << b;
  }
  if (s.machining) {
    const auto& m = *s.machining;
    if (m.spindle_rpm <= 0.0) {
      os << "  machining: spindle stopped at the end; depth " << m.depth_mm << " mm\n";
    } else {
      std::snprintf(
          b, sizeof b,
          "  machining at the end: %.0f rpm, depth %.3f mm; limit open %.3f mm (SDM), damped %.3f mm (%s)%s; chatter "
          "indicator %s (once-per-rev %.2f, non-harmonic %.0f %%)%s\n",
          m.spindle_rpm, m.depth_mm, m.open_limit_mm, m.damped_limit_mm, m.limit_method.c_str(),
          !m.limits_ready    ? " (not computed)"
          : !m.depth_warning ? ""
          : m.depth_measured ? ": WARNING, depth above the limit"
          : m.cutting == dds::kNotCutting
              ? ": the job's planned depth is above the limit here (not cutting)"
              : ": WARNING, the job's planned depth is above the limit (the robot reports no depth)",
          !m.indicator_valid ? "not ready"
          : m.chatter        ? "CHATTER"
                             : "quiet",
          m.once_per_rev_ratio, 100.0 * m.nonharmonic_share,
          m.cutting == dds::kCutting      ? "; cutting"
          : m.cutting == dds::kNotCutting ? ("; NOT CUTTING (" + m.cutting_reason + ")").c_str()
                                          : "");
      os << b;
      if (!m.limits_pose_deg.empty())
        os << "  the limits are at the robot's pose " << config::describe_pose(m.limits_pose_deg) << "\n";
      if (m.mode_spread_pct >= 0.0) {
        char spread[160];
        std::snprintf(spread, sizeof spread,
                      "  its modes there from the measured map: +-%.2f %% in frequency (one sigma), %.1f deg from the "
                      "nearest measured pose\n",
                      m.mode_spread_pct, m.nearest_measured_deg);
        os << spread;
      }
    }
  }
  if (!s.limits_trail.empty()) {
    os << "  limits along the path (" << s.limits_trail.size() << " states):\n";
    for (const auto& r : s.limits_trail) {
      std::snprintf(b, sizeof b,
                    "    %8.2f s  %-24s %6.0f rpm  set %zu  K %5.0f N s/m: open %.3f mm, damped %.3f mm%s\n", r.time_s,
                    r.limits.pose_deg.empty() ? "pose not known" : config::describe_pose(r.limits.pose_deg).c_str(),
                    r.limits.rpm, r.set, r.gain_ns_per_m, r.limits.open_mm, r.limits.damped_mm,
                    !r.limits.damped_valid         ? " (the loop is unstable here)"
                    : r.limits.loop_model_verified ? ""
                                                   : " (the damped model is not verified here: not claimed)");
      os << b;
    }
  }
  if (s.advice) os << advice_text(runtime::to_sample(*s.advice));
  if (!s.realtime.warnings.empty())
    os << "  real-time set-up: " << s.realtime.warnings.size() << " step(s) fell back (warnings at start)\n";
  return os.str();
}

bool write_latency_histogram(const std::string& path, const runtime::RunSummary& s) {
  std::ofstream out(path);
  const auto& h = s.loop.wake_latency;
  out << "# robodamp run wake-up latency histogram (us)\n";
  std::size_t last = 0;
  for (std::size_t us = 0; us < rt::TimingHistogram::kBins; ++us)
    if (h.bin(us) > 0) last = us;
  char line[64];
  for (std::size_t us = 0; us <= last; ++us) {
    std::snprintf(line, sizeof line, "%06zu %06llu\n", us, static_cast<unsigned long long>(h.bin(us)));
    out << line;
  }
  out << "# Total: " << h.count() << "\n# Max Latencies: " << h.max_us() << "\n# Histogram Overflows: " << h.overflow()
      << "\n# Loop overruns: " << s.loop.overruns << "\n# Missed ticks: " << s.loop.missed_ticks << '\n';
  return static_cast<bool>(out);
}

}  // namespace robodamp::runtime
