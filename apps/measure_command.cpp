// `robodamp measure`: the commissioning measurement (docs/identification.md, "Commissioning"). The
// configured cell runs with control off (K = 0) and the amplifier enabled, through the same loop and
// drivers as `robodamp run`: a periodic chirp on the actuator, kept inside the force and voltage limits
// the configuration gives, then hammer impacts at every location. The loop records every tick; the
// plant side writes the impact FRFs (in process for the simulated plant; `robodamp plant --measure-out
// DIR` with hardware). `robodamp identify all --in DIR` turns the directory into a configuration.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <spdlog/spdlog.h>

#include "analysis/modal_test.hpp"
#include "apps/cli.hpp"
#include "identify/commissioning.hpp"
#include "rt/signals.hpp"
#include "runtime/cell.hpp"

namespace robodamp::apps {

namespace {

namespace fs = std::filesystem;

struct MeasureArgs {
  std::string config_path{ROBODAMP_DEFAULT_CONFIG};
  std::string out_dir;
  std::string clock;
};

// The plant-side instruments stepped with the simulated plant.
class ModalTestHook final : public drivers::PlantStepHook {
 public:
  explicit ModalTestHook(analysis::ModalTest& t) : t_(t) {}
  void before_step(std::uint64_t k) noexcept override { t_.before_step(static_cast<std::size_t>(k)); }
  void after_step(std::uint64_t k) noexcept override { t_.after_step(static_cast<std::size_t>(k)); }

 private:
  analysis::ModalTest& t_;
};

// One progress line per phase of the plan, from the drained frames' loop time.
class Progress {
 public:
  explicit Progress(const analysis::CommissioningPlan& p, const std::vector<std::pair<int, std::string>>& locations,
                    double chirp_period_s)
      : plan_(p), locations_(locations), period_s_(chirp_period_s) {}
  void on_frame(const rt::TelemetryFrame& f) {
    const int phase = phase_at(f.time_s);
    if (phase == last_) return;
    last_ = phase;
    const std::size_t n_chirp = static_cast<std::size_t>(std::lround((plan_.chirp_end_s - plan_.chirp_start_s) / period_s_));
    if (phase == 0) return;
    if (phase <= static_cast<int>(n_chirp)) {
      spdlog::info("robodamp measure: {:.1f} s chirp period {} of {} ({}), state {}", f.time_s, phase, n_chirp,
                   phase == 1 ? "transient, discarded" : "averaged", rt::to_string(static_cast<rt::State>(f.state)));
    } else if (phase <= static_cast<int>(n_chirp + locations_.size())) {
      const auto& l = locations_[static_cast<std::size_t>(phase) - n_chirp - 1];
      spdlog::info("robodamp measure: {:.1f} s impacts at the {} (location {})", f.time_s, l.second, l.first);
    }
  }

 private:
  int phase_at(double t) const {
    if (t < plan_.chirp_start_s) return 0;
    if (t < plan_.chirp_end_s) return 1 + static_cast<int>((t - plan_.chirp_start_s) / period_s_);
    const int chirp = static_cast<int>(std::lround((plan_.chirp_end_s - plan_.chirp_start_s) / period_s_));
    int k = 0;
    for (std::size_t i = 0; i < plan_.impacts_start_s.size(); ++i)
      if (t >= plan_.impacts_start_s[i]) k = static_cast<int>(i) + 1;
    return k == 0 ? chirp + 100 : chirp + k;  // the quiet gap: no line
  }
  analysis::CommissioningPlan plan_;
  std::vector<std::pair<int, std::string>> locations_;
  double period_s_;
  int last_{-1};
};

// The share of the chirp's ticks with the loop active (the test signal only plays there).
double chirp_active_share(const std::vector<rt::TelemetryFrame>& frames, const analysis::CommissioningPlan& p) {
  std::size_t in = 0, active = 0;
  for (const auto& f : frames) {
    if (f.time_s < p.chirp_start_s || f.time_s >= p.chirp_end_s) continue;
    ++in;
    if (f.state == static_cast<std::uint8_t>(rt::State::kActive)) ++active;
  }
  return in == 0 ? 0.0 : static_cast<double>(active) / static_cast<double>(in);
}

int measure(const MeasureArgs& a) {
  const config::Config cfg = config::load_config_file(a.config_path);
  const sim::PlantModel model = sim::build_plant_model(cfg);
  const analysis::CommissioningPlan plan = analysis::commissioning_plan(cfg, model);
  fs::create_directories(a.out_dir);

  config::Config off = cfg;  // control off: the loop runs, the controller's gain is 0
  off.controller.gain_ns_per_m = 0.0;
  const auto& c = cfg.commissioning;
  runtime::CellOptions o;
  if (!a.clock.empty()) o.clock = a.clock == "wall" ? config::ClockKind::kWall : config::ClockKind::kVirtual;
  else if (!cfg.can) o.clock = config::ClockKind::kVirtual;  // the simulated plant: nothing to pace
  o.record_path = (fs::path(a.out_dir) / identify::kRecordingName).string();
  o.keep_frames = true;
  o.test_signal = {true, plan.chirp_start_s, c.chirp_period_s, c.chirp_periods, c.chirp_f0_hz, c.chirp_f1_hz,
                   plan.chirp_amplitude_v, cfg.amplifier.voltage_limit_v};
  identify::MeasurementManifest m;
  m.config_source = fs::absolute(a.config_path).lexically_normal().string();
  m.config_text = cfg.yaml_text;
  m.loop_rate_hz = cfg.loop.rate_hz;
  m.plan = plan;
  for (const auto& l : cfg.robot.locations) m.locations.emplace_back(l.id, l.name);
  m.sensor_location_id = cfg.sensor.location;
  m.actuator_location_id = model.locations[model.actuator.location].id;
  Progress progress(plan, m.locations, c.chirp_period_s);
  o.on_frame = [&progress](const rt::TelemetryFrame& f) { progress.on_frame(f); };

  runtime::Cell cell(off, o);
  if (runtime::Status s = cell.configure(); !s.ok()) {
    std::cerr << s.message << '\n';
    return s.kind == runtime::StatusKind::kConfigError ? 2 : 1;
  }
  m.backend = cell.hardware() ? "hardware" : "simulated plant";
  std::unique_ptr<analysis::ModalTest> test;
  std::unique_ptr<ModalTestHook> hook;
  if (!cell.hardware()) {
    test = std::make_unique<analysis::ModalTest>(cfg, cell.plant(), plan);
    hook = std::make_unique<ModalTestHook>(*test);
    cell.sim_backend().set_step_hook(hook.get());
  }
  rt::install_shutdown_handlers();
  spdlog::info("robodamp measure: {} on {}, {:.0f} s: control off, chirp {:.1f}-{:.1f} Hz at {:.3f} V from {:.1f} s "
               "(predicted peak actuator force {:.1f} N of {:.0f} N), then {} impacts of {:.0f} N at each of {} locations",
               a.config_path, m.backend, plan.duration_s, c.chirp_f0_hz, c.chirp_f1_hz, plan.chirp_amplitude_v,
               plan.chirp_start_s, plan.predicted_peak_force_n, cfg.actuator.force_limit_n, c.impacts_per_location,
               cfg.bench.impact_peak_n, m.locations.size());
  if (runtime::Status s = cell.activate(plan.duration_s); !s.ok()) {
    std::cerr << "robodamp measure: " << s.message << '\n';
    return 1;
  }
  cell.wait();
  if (runtime::Status s = cell.deactivate(); !s.ok()) std::cerr << "robodamp measure: " << s.message << '\n';
  const runtime::RunSummary& s = cell.summary();
  const double active = chirp_active_share(cell.frames(), plan);
  m.run = {{"final_state", s.final_state}, {"trip", s.trip}, {"saturated_ticks", s.supervisor.saturated_ticks},
           {"peak_command_v", s.peak_command_v}, {"chirp_active_share", active},
           {"recorded_frames", s.recorded_frames}, {"record_errors", s.record_errors}};
  if (test) {
    const auto files = test->write_frf_csvs(a.out_dir);
    m.run["impact_records"] = test->records();
    std::cout << "robodamp measure: " << test->records() << " of " << test->records_planned() << " impact records; wrote "
              << files.size() << " FRFs to " << a.out_dir << '\n';
  } else {
    std::cout << "robodamp measure: the plant side (robodamp plant --measure-out " << a.out_dir
              << ") writes the impact FRFs when the run ends\n";
  }
  {
    std::ofstream out(fs::path(a.out_dir) / identify::kManifestName);
    out << identify::to_json(m).dump(2) << '\n';
    if (!out) {
      std::cerr << "robodamp measure: cannot write " << (fs::path(a.out_dir) / identify::kManifestName).string() << '\n';
      return 1;
    }
  }
  std::printf("robodamp measure: state %s, trip %s, chirp played with the loop active over %.1f %% of its ticks, "
              "%llu saturated ticks, peak command %.3f V, %llu frames recorded\n",
              s.final_state.c_str(), s.trip.c_str(), 100.0 * active,
              static_cast<unsigned long long>(s.supervisor.saturated_ticks), s.peak_command_v,
              static_cast<unsigned long long>(s.recorded_frames));
  if (s.trip != "none") {
    std::cerr << "robodamp measure: the loop tripped (" << s.trip << " - " << s.trip_description
              << "): the measurement is incomplete\n";
    return 4;
  }
  if (active < 1.0) {
    std::cerr << "robodamp measure: the loop was not active for the whole chirp (" << 100.0 * active
              << " % of its ticks): raise commissioning.settle_s or look at the arming refusals\n";
    return 5;
  }
  if (s.record_errors > 0) return 1;
  return 0;
}

}  // namespace

void register_measure(Registry& r) {
  auto a = std::make_shared<MeasureArgs>();
  CLI::App* sub = r.add("measure",
                        "Commissioning measurement: control off, amplifier on, a chirp on the actuator and hammer impacts "
                        "at every location, recorded for `identify all`",
                        [a] { return measure(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML)")->check(CLI::ExistingFile);
  sub->add_option("--out", a->out_dir, "Directory for the recording, the FRFs and measurement.json")->required();
  sub->add_option("--clock", a->clock, "Override loop.clock: wall (real time) or virtual (as fast as possible)")
      ->check(CLI::IsMember({"wall", "virtual"}));
}

}  // namespace robodamp::apps
