// The emulator's report as JSON and as the text `robodamp plant` prints (hil/plant_emulator.hpp).
#include <cmath>
#include <cstdio>
#include <string>
#include <sstream>

#include "hil/plant_emulator.hpp"

#include <spdlog/fmt/fmt.h>

namespace robodamp::hil {

namespace {

nlohmann::json advice_json(const std::vector<AdviceSeen>& advice) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& a : advice)
    out.push_back({{"plant_time_s", a.plant_time_s},
                   {"seq", a.seq},
                   {"status", a.status},
                   {"rpm", a.rpm},
                   {"margin", a.margin},
                   {"action", a.action}});
  return out;
}

}  // namespace

nlohmann::json report_json(const EmulatorReport& r) {
  using nlohmann::json;
  json frfs = json::array();
  for (const auto& f : r.frfs)
    frfs.push_back({{"name", f.name},
                    {"open_peak_m_per_n", f.open_peak_m_per_n},
                    {"open_peak_hz", f.open_peak_hz},
                    {"closed_peak_m_per_n", f.closed_peak_m_per_n},
                    {"closed_peak_hz", f.closed_peak_hz},
                    {"measured_improvement_pct", f.improvement_pct},
                    {"coherence_min", f.coherence_min}});
  json dwells = json::array();
  for (const auto& d : r.pose_dwells)
    dwells.push_back({{"joints_deg", d.joints_deg},
                      {"t0_s", d.t0_s},
                      {"t1_s", d.t1_s},
                      {"region", d.region},
                      {"dominant_hz", d.dominant_hz},
                      {"records", d.records},
                      {"open_peak_m_per_n", d.open_peak_m_per_n},
                      {"closed_peak_m_per_n", d.closed_peak_m_per_n},
                      {"closed_peak_hz", d.closed_peak_hz},
                      {"measured_improvement_pct", d.improvement_pct},
                      {"predicted_improvement_pct", d.predicted_pct},
                      {"coherence_min", d.coherence_min}});
  const auto& h = r.wake_latency;
  return {
      {"config", r.config},
      {"pose", {{"retunes", r.pose_retunes}, {"dwells", dwells}}},
      {"pacing", r.pacing},
      {"transport", r.transport},
      {"modbus", r.modbus},
      {"ticks", r.ticks},
      {"plant_time_s", r.plant_time_s},
      {"elapsed_s", r.elapsed_s},
      {"end_reason", r.end_reason},
      {"cutting", cutting_json(r.cutting)},
      {"regenerative_cut", regenerative_cut_json(r.regenerative_cut)},
      {"advice", advice_json(r.advice)},
      {"measurement",
       {{"records", r.measure_records}, {"records_planned", r.measure_records_planned}, {"files", r.measure_files}}},
      {"frames",
       {{"sensor_sent", r.sensor_frames_sent},
        {"send_errors", r.send_errors},
        {"commands", r.command_frames},
        {"commands_lost", r.commands_lost},
        {"malformed", r.frames_malformed},
        {"other_ids", r.frames_other},
        {"held_periods", r.held_periods}}},
      {"amplifier",
       {{"enable_changes", r.enable_changes},
        {"enabled_s", r.enabled_s},
        {"peak_command_v", r.peak_command_v},
        {"peak_temperature_c", r.peak_temperature_c}}},
      {"robot", {{"mounting_changes", r.mounting_changes}, {"spindle_changes", r.spindle_changes}}},
      {"injected",
       [&r] {
         json a = json::array();
         for (const auto& f : r.injected)
           a.push_back({{"kind", f.kind}, {"plant_time_s", f.plant_time_s}, {"monotonic_ns", f.monotonic_ns}});
         return a;
       }()},
      {"modbus_requests", r.modbus_requests},
      {"timing",
       {{"wake_latency",
         {{"count", h.count()},
          {"p50_us", h.percentile_us(0.5)},
          {"p99_us", h.percentile_us(0.99)},
          {"max_us", h.max_us()}}},
        {"overruns", r.overruns}}},
      {"impacts",
       {{"location", r.impact_location},
        {"started", r.campaign_started},
        {"complete", r.campaign_complete},
        {"start_s", r.campaign_start_s},
        {"records", r.records},
        {"records_planned", r.records_planned},
        {"frfs", frfs}}}};
}

// long: one line per field of the emulator's report, in reading order
std::string report_text(const EmulatorReport& r) {
  std::ostringstream os;
  char b[400];
  std::snprintf(b, sizeof b, "robodamp plant: %s, %s pacing over %s; Modbus %s\n", r.config.c_str(), r.pacing.c_str(),
                r.transport.c_str(), r.modbus.c_str());
  os << b;
  std::snprintf(b, sizeof b, "  %llu plant steps (%.3f s plant time) in %.3f s; ended: %s\n",
                static_cast<unsigned long long>(r.ticks), r.plant_time_s, r.elapsed_s, r.end_reason.c_str());
  os << b;
  std::snprintf(
      b, sizeof b,
      "  frames: %llu sensor sent (%llu send errors), %llu commands (%llu lost, %llu malformed, %llu other ids)%s\n",
      static_cast<unsigned long long>(r.sensor_frames_sent), static_cast<unsigned long long>(r.send_errors),
      static_cast<unsigned long long>(r.command_frames), static_cast<unsigned long long>(r.commands_lost),
      static_cast<unsigned long long>(r.frames_malformed), static_cast<unsigned long long>(r.frames_other),
      r.pacing == "realtime" ? (", " + std::to_string(r.held_periods) + " periods held the last command").c_str() : "");
  os << b;
  if (r.pacing == "realtime") {
    const auto& h = r.wake_latency;
    std::snprintf(b, sizeof b, "  emulator wake-up latency: p50 %.0f us, p99 %.0f us, max %.1f us; %llu overruns\n",
                  h.percentile_us(0.5), h.percentile_us(0.99), h.max_us(), static_cast<unsigned long long>(r.overruns));
    os << b;
  }
  std::snprintf(b, sizeof b,
                "  amplifier: enabled %.3f s (%llu changes), peak drive %.3f V, peak %.1f degC; %llu Modbus requests\n",
                r.enabled_s, static_cast<unsigned long long>(r.enable_changes), r.peak_command_v, r.peak_temperature_c,
                static_cast<unsigned long long>(r.modbus_requests));
  os << b;
  if (r.measure_records_planned > 0) {
    std::snprintf(b, sizeof b, "  commissioning impacts: %d of %d records; %zu FRFs written\n", r.measure_records,
                  r.measure_records_planned, r.measure_files.size());
    os << b;
  }
  if (r.records_planned > 0) {
    std::snprintf(b, sizeof b, "  impacts at the %s: %d of %d records%s\n", r.impact_location.c_str(), r.records,
                  r.records_planned, r.campaign_complete ? "" : " (incomplete: the controller left first)");
    os << b;
    for (const auto& f : r.frfs) {
      std::snprintf(
          b, sizeof b,
          "    %-8s open %.4g m/N at %.2f Hz, closed %.4g m/N at %.2f Hz: improvement %.1f %% (coherence min %.4f)\n",
          f.name.c_str(), f.open_peak_m_per_n, f.open_peak_hz, f.closed_peak_m_per_n, f.closed_peak_hz,
          f.improvement_pct, f.coherence_min);
      os << b;
    }
  }
  if (!r.pose_dwells.empty()) {
    std::snprintf(b, sizeof b, "  pose trajectory: the plant's modes retuned %llu times\n",
                  static_cast<unsigned long long>(r.pose_retunes));
    os << b;
  }
  for (const auto& d : r.pose_dwells) {
    std::string q;
    for (double v : d.joints_deg) {
      if (!q.empty()) q += ' ';
      q += std::to_string(std::lround(v));
    }
    std::snprintf(
        b, sizeof b,
        "    dwell %.1f-%.1f s at [%s] deg (region '%s', dominant mode %.2f Hz): %d records, open %.4g m/N, closed "
        "%.4g m/N at %.2f Hz: improvement %.1f %% measured, %.1f %% predicted (coherence min %.3f)\n",
        d.t0_s, d.t1_s, q.c_str(), d.region.c_str(), d.dominant_hz, d.records, d.open_peak_m_per_n,
        d.closed_peak_m_per_n, d.closed_peak_hz, d.improvement_pct, d.predicted_pct, d.coherence_min);
    os << b;
  }
  if (r.cutting.cut) {
    const auto& c = r.cutting;
    const auto at = [](const std::vector<double>& v, std::size_t i) { return i < v.size() ? v[i] : 0.0; };
    std::snprintf(
        b, sizeof b,
        "  cutting %s: %.3f s in the cut (last %.0f rpm), %.3f s of it at the actuator's limits; command at "
        "1/2/3 x tooth passing %.3g / %.3g / %.3g V over %.1f s at a steady speed (force %.1f / %.1f / %.1f N)\n",
        c.job.c_str(), c.in_cut_s, c.last_rpm, c.saturated_in_cut_s, at(c.command_harmonics_v, 0),
        at(c.command_harmonics_v, 1), at(c.command_harmonics_v, 2), c.measured_s, at(c.force_harmonics_n, 0),
        at(c.force_harmonics_n, 1), at(c.force_harmonics_n, 2));
    os << b;
  }
  if (r.regenerative_cut.cut) {
    const auto& c = r.regenerative_cut;
    const auto& v = c.verdict;
    if (!c.complete)
      std::snprintf(b, sizeof b,
                    "  regenerative cut %s: %.3f mm at %.1f rpm from %.3f s: incomplete (the run ended at %.3f s)\n",
                    c.job.c_str(), c.axial_mm, c.rpm, c.start_s, c.end_s);
    else
      std::snprintf(b, sizeof b,
                    "  regenerative cut %s: %.3f mm at %.1f rpm, %d revolutions from %.3f s: %s (%s), chatter %.2f Hz, "
                    "growth %.4f per tooth, non-harmonic energy %.3f, peak force %.1f N\n",
                    c.job.c_str(), c.axial_mm, c.rpm, c.revolutions, c.start_s, milling::to_string(v.classification),
                    milling::to_string(v.mechanism), v.chatter_hz, v.growth_per_period, v.nonharmonic_energy_ratio,
                    c.peak_force_n);
    os << b;
    if (c.segments.size() > 1)
      for (const auto& g : c.segments) {
        std::snprintf(
            b, sizeof b, "    %.3f-%.3f s (%s): %.3f mm at %.1f rpm, %.1f revolutions: %s%s\n", g.start_s, g.end_s,
            g.cause.c_str(), g.axial_mm, g.rpm, g.revolutions,
            g.judged ? milling::to_string(g.verdict.classification) : "too short to judge",
            g.judged && g.verdict.chatter_hz > 0.0 ? fmt::format(" at {:.2f} Hz", g.verdict.chatter_hz).c_str() : "");
        os << b;
      }
  }
  for (const auto& a : r.advice) {
    std::snprintf(b, sizeof b, "  advice #%u read at %.3f s: status %d, %.1f rpm, margin %.2f: %s\n", a.seq,
                  a.plant_time_s, a.status, a.rpm, a.margin, a.action.c_str());
    os << b;
  }
  for (const auto& f : r.injected) {
    std::snprintf(b, sizeof b, "  injected %s at %.3f s plant time\n", f.kind.c_str(), f.plant_time_s);
    os << b;
  }
  return os.str();
}

}  // namespace robodamp::hil
