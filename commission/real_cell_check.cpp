#include "commission/real_cell_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "analysis/loop_model.hpp"
#include "commission/cell_check.hpp"
#include "commission/emulated_cell.hpp"
#include "identify/actuator_fit.hpp"
#include "rt/excitation.hpp"
#include "rt/recording.hpp"
#include "units/units.hpp"

namespace robodamp::commission {

namespace {

using Complex = std::complex<double>;

double db(double x) { return 20.0 * std::log10(x); }
double deg_of(Complex z) { return std::arg(z) * 360.0 / kTwoPi; }
double wrap_deg(double d) { return std::remainder(d, 360.0); }

// The largest |H| within +-10 % of f_hz on the grid (0 when no point is there).
double peak_near(const std::vector<double>& f_hz, const std::vector<double>& mag, double f0) {
  double best = 0.0;
  for (std::size_t i = 0; i < f_hz.size(); ++i)
    if (std::abs(f_hz[i] - f0) <= 0.1 * f0) best = std::max(best, mag[i]);
  return best;
}

Complex ratio(const analysis::FrfEstimate& a, const analysis::FrfEstimate& b, std::size_t i) {
  return a.h1[i] / b.h1[i];
}

void compare_loop(LoopGainCheck& c, double min_coherence) {
  for (std::size_t i = 0; i < c.f_hz.size(); ++i) {
    const double p = std::abs(c.predicted[i]);
    if (c.coherence[i] < min_coherence || p < 0.1 || p > 10.0) continue;
    ++c.compared_points;
    const double e_db = std::abs(db(std::abs(c.measured[i]) / p));
    const double e_deg = std::abs(wrap_deg(deg_of(c.measured[i]) - deg_of(c.predicted[i])));
    if (e_db > c.max_error_db) c.max_error_db = e_db, c.error_db_at_hz = c.f_hz[i];
    if (e_deg > c.max_error_deg) c.max_error_deg = e_deg, c.error_deg_at_hz = c.f_hz[i];
  }
}

}  // namespace

ChirpLoopFrfs read_chirp_loop(const std::string& path) {
  if (!std::filesystem::exists(path))
    throw std::invalid_argument(path + " is missing: robodamp measure records the loop there");
  const rt::Recording rec = rt::read_recording(path);
  const rt::PeriodicChirp chirp = rt::excitation_from(rec.header);
  if (!chirp.enabled)
    throw std::invalid_argument(path + " holds no chirp (a robodamp run recording, not a robodamp measure one)");
  if (rec.frames.empty()) throw std::invalid_argument(path + " holds no frames");
  ChirpLoopFrfs m;
  m.fs_hz = rec.header.at("rate_hz");
  m.f0_hz = chirp.f0_hz, m.f1_hz = chirp.f1_hz;
  // By tick, the chirp regenerated on the loop's clock as replay does; a skipped tick holds its neighbour.
  const std::uint64_t n = rec.frames.back().tick + 1;
  std::vector<double> e(n, 0.0), u(n, 0.0), c(n, 0.0), y(n, 0.0);
  rt::ExcitationClock clock(chirp);
  std::uint64_t next = 0;
  for (const auto& f : rec.frames) {
    for (; next < f.tick; ++next)
      if (next > 0) e[next] = e[next - 1], u[next] = u[next - 1], c[next] = c[next - 1], y[next] = y[next - 1];
    e[f.tick] = clock.next_v(f.dt_s), u[f.tick] = f.command_v, c[f.tick] = f.controller_v, y[f.tick] = f.accel_mps2;
    next = f.tick + 1;
  }
  const auto period_n = static_cast<std::size_t>(std::lround(chirp.period_s * m.fs_hz));
  const auto first =
      static_cast<std::size_t>(std::lround(chirp.start_s * m.fs_hz)) + period_n;  // the first period: transient
  m.periods_averaged = chirp.periods - 1;
  if (first + period_n * static_cast<std::size_t>(m.periods_averaged) > n)
    throw std::invalid_argument(path + ": the recording ends before the chirp's last period");
  m.accel = identify::periodic_frf(e, y, first, period_n, m.periods_averaged, m.fs_hz, chirp.f1_hz);
  m.command = identify::periodic_frf(e, u, first, period_n, m.periods_averaged, m.fs_hz, chirp.f1_hz);
  m.controller = identify::periodic_frf(e, c, first, period_n, m.periods_averaged, m.fs_hz, chirp.f1_hz);
  return m;
}

std::pair<std::optional<double>, std::optional<double>> margins_on_grid(const std::vector<double>& f_hz,
                                                                        const std::vector<Complex>& l) {
  std::optional<double> gm, pm;
  for (std::size_t i = 1; i < f_hz.size(); ++i) {
    const Complex a = l[i - 1], b = l[i];
    // Phase crossover: L crosses the negative real axis (Im changes sign with Re < 0).
    if ((a.imag() <= 0.0) != (b.imag() <= 0.0)) {
      const double t = a.imag() / (a.imag() - b.imag());
      const Complex x = a + t * (b - a);
      if (x.real() < 0.0) {
        const double g = -db(-x.real());
        if (!gm || g < *gm) gm = g;
      }
    }
    // Gain crossover: |L| crosses 1; the phase margin is the angle from -1.
    const double ma = std::abs(a), mb = std::abs(b);
    if ((ma < 1.0) != (mb < 1.0)) {
      const double t = (1.0 - ma) / (mb - ma);
      const Complex x = a + t * (b - a);
      const double p = 180.0 - std::abs(deg_of(x));
      if (!pm || p < *pm) pm = p;
    }
  }
  return {gm, pm};
}

bool LoopGainCheck::holds() const {
  return compared_points > 0 && max_error_db <= tolerance_db && max_error_deg <= tolerance_deg;
}

std::string RealCellCheck::failure() const {
  char b[400];
  if (!run_problem.empty()) return run_problem;
  if (closed_trip != "none") return "the cell tripped with the tuned controller (" + closed_trip + ")";
  if (open_trip != "none") return "the cell tripped with control off (" + open_trip + ")";
  if (closed_active_share < 1.0) {
    std::snprintf(b, sizeof b, "the loop was active over only %.1f %% of the control-on chirp",
                  100.0 * closed_active_share);
    return b;
  }
  for (const auto& m : modes)
    if (!(std::abs(m.measured_improvement_pct - m.predicted_improvement_pct) <= improvement_tolerance_points)) {
      std::snprintf(b, sizeof b,
                    "the mode at %.2f Hz at the actuator: measured improvement %.1f %% against %.1f %% predicted "
                    "(allowed +-%.0f points)",
                    m.freq_hz, m.measured_improvement_pct, m.predicted_improvement_pct, improvement_tolerance_points);
      return b;
    }
  const LoopGainCheck& l = loop_gain;
  if (l.compared_points == 0) return "the loop gain: no coherent point between |L| = 0.1 and 10 in the chirp's band";
  if (!l.holds()) {
    std::snprintf(b, sizeof b,
                  "the measured loop gain differs from the analysis by %.2f dB (at %.1f Hz) and %.1f deg (at %.1f "
                  "Hz); allowed %.0f dB and %.0f deg",
                  l.max_error_db, l.error_db_at_hz, l.max_error_deg, l.error_deg_at_hz, l.tolerance_db,
                  l.tolerance_deg);
    return b;
  }
  return {};
}

std::vector<std::string> RealCellCheck::progress_lines() const {
  std::vector<std::string> out;
  char b[512];
  for (const auto& m : modes) {
    std::snprintf(b, sizeof b,
                  "on the cell, the mode at %.2f Hz at the actuator: improvement %.1f %% measured, %.1f %% predicted",
                  m.freq_hz, m.measured_improvement_pct, m.predicted_improvement_pct);
    out.emplace_back(b);
  }
  const LoopGainCheck& g = loop_gain;
  auto margin = [](const std::optional<double>& v, const char* unit) {
    char m[64];
    std::snprintf(m, sizeof m, "%.1f %s", v.value_or(0.0), unit);
    return v ? std::string(m) : std::string("(no crossover in the chirp's band)");
  };
  std::snprintf(b, sizeof b,
                "the loop gain measured on the cell (the chirp injected at the plant's input, %d lines): within "
                "%.2f dB and %.1f deg of the analysis; margins measured GM %s, PM %s; the analysis on the same lines "
                "GM %s, PM %s",
                g.compared_points, g.max_error_db, g.max_error_deg, margin(g.measured_gm_db, "dB").c_str(),
                margin(g.measured_pm_deg, "deg").c_str(), margin(g.predicted_gm_db, "dB").c_str(),
                margin(g.predicted_pm_deg, "deg").c_str());
  out.emplace_back(b);
  return out;
}

std::string RealCellCheck::header_lines() const {
  std::string h = "# Verified on " + cell + " with the actuator's chirp, control off and on:";
  char b[200];
  for (const auto& m : modes) {
    std::snprintf(b, sizeof b, " the mode at %.2f Hz at the actuator improved %.1f %% (%.1f %% predicted);", m.freq_hz,
                  m.measured_improvement_pct, m.predicted_improvement_pct);
    h += b;
  }
  std::snprintf(b, sizeof b, " the loop gain within %.2f dB and %.1f deg of the analysis.", loop_gain.max_error_db,
                loop_gain.max_error_deg);
  h += b;
  h += "\n# No hammer and no cut on the machine: the depths above are the identified model's promise; cut a test part "
       "with `robodamp chatter` listening to check them.";
  return h;
}

RealCellCheck check_real_cell(const ChirpLoopFrfs& off, const ChirpLoopFrfs& on, const config::Config& tuned,
                              const std::vector<double>& modes_hz, double min_coherence) {
  if (off.accel.f_hz.size() != on.accel.f_hz.size())
    throw std::invalid_argument("the control-off and control-on chirps differ in their frequency lines");
  RealCellCheck r;
  const analysis::LoopModel model(tuned);
  const double k = tuned.controller.gain_ns_per_m;
  const int pol = tuned.controller.polarity;
  const double lo = std::max(tuned.analysis.band_min_hz, on.f0_hz), hi = std::min(tuned.analysis.band_max_hz, on.f1_hz);
  LoopGainCheck& g = r.loop_gain;
  for (std::size_t i = 0; i < on.accel.f_hz.size(); ++i) {
    const double f = on.accel.f_hz[i];
    if (f < lo || f > hi) continue;
    const analysis::PlantResponse p = model.plant_response(f);
    const Complex l = model.loop_discrete(p, model.chain_filters_digital(f), k, pol);
    const Complex open = p.accel_per_volt[model.sensor_location()];
    r.f_hz.push_back(f);
    r.measured_open.push_back(std::abs(off.accel.h1[i]));
    r.measured_closed.push_back(std::abs(on.accel.h1[i]));
    r.predicted_open.push_back(std::abs(open));
    r.predicted_closed.push_back(std::abs(open / (1.0 + l)));
    g.f_hz.push_back(f);
    g.measured.push_back(-ratio(on.controller, on.command, i));
    g.predicted.push_back(l);
    g.coherence.push_back(std::min(on.command.coherence[i], on.controller.coherence[i]));
  }
  compare_loop(g, min_coherence);
  std::tie(g.measured_gm_db, g.measured_pm_deg) = margins_on_grid(g.f_hz, g.measured);
  std::tie(g.predicted_gm_db, g.predicted_pm_deg) = margins_on_grid(g.f_hz, g.predicted);
  for (const double f0 : modes_hz) {
    if (f0 < lo || f0 > hi) continue;
    ModeCheckAtActuator m;
    m.freq_hz = f0;
    m.measured_improvement_pct =
        100.0 * (peak_near(r.f_hz, r.measured_open, f0) / peak_near(r.f_hz, r.measured_closed, f0) - 1.0);
    m.predicted_improvement_pct =
        100.0 * (peak_near(r.f_hz, r.predicted_open, f0) / peak_near(r.f_hz, r.predicted_closed, f0) - 1.0);
    r.modes.push_back(m);
  }
  return r;
}

RealCellCheck verify_on_real_cell(const config::Config& cell, const config::Config& tuned,
                                  const std::vector<double>& modes_hz, const RealCellRun& run,
                                  MeasureOutcome& chirp_on) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string out = (std::filesystem::path(run.work_dir) / "chirp_on").string();
  MeasureOptions o;
  o.impacts = false;
  o.control_on = true;
  const config::Config controller = with_controller_of(cell, tuned);
  chirp_on = run.binary.empty() ? measure(controller, run.cell_path, out, o)
                                : measure_through_emulator(run.cell_path, out, run.binary, {o, controller});
  const std::string rec = std::string("/") + identify::kRecordingName;
  if (chirp_on.status != MeasureStatus::kOk) {
    RealCellCheck r;
    r.run_problem = "the chirp with the tuned controller: " + chirp_on.message;
    r.closed_trip = chirp_on.trip;
    return r;
  }
  RealCellCheck r =
      check_real_cell(read_chirp_loop(run.measurement_dir + rec), read_chirp_loop(out + rec), tuned, modes_hz);
  r.cell =
      run.binary.empty()
          ? (cell.can ? "the cell on " + cell.can->interface + " (no hammer, no cut)"
                      : std::string("the simulated plant in process, as a real cell (no hammer, no cut)"))
          : "the HIL emulator as a real cell (robodamp plant --no-impacts, no cut) through the CAN and Modbus drivers";
  r.open_trip = identify::read_manifest(run.measurement_dir).run.value("trip", std::string("none"));
  r.closed_trip = chirp_on.trip;
  r.closed_active_share = chirp_on.chirp_active_share;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// Why a cell may not be measured with robodamp's own hammer (empty: it may, the emulator's CAN over a socket).
std::string hardware_refusal(const config::Config& cell) {
  if (!cell.can || cell.can->interface.rfind("unix:", 0) == 0) return {};
  return "the cell is a CAN bus (can.interface = " + cell.can->interface +
         "): robodamp orders no hammer blow and no cut on a real cell; give your modal kit's tap tests with "
         "--tap-tests "
         "FILE... (UFF or frf_<response>_<excitation>.csv) and it commissions with the actuator as the shaker";
}

}  // namespace robodamp::commission
