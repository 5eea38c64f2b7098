// The plant emulator's end (hil/plant_emulator_class.hpp): its report, the measurements written, and the
// impact campaign's open-loop reference run in process.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>

#include <spdlog/spdlog.h>

#include "analysis/bench_run.hpp"
#include "hil/plant_emulator.hpp"
#include "hil/plant_emulator_class.hpp"
#include "sim_plant/plant.hpp"

namespace robodamp::hil::detail {

EmulatorReport PlantEmulator::finish() {
  rep_.plant_time_s = static_cast<double>(rep_.ticks) * dt_;
  rep_.elapsed_s = std::chrono::duration<double>(Clock::now() - wall0_).count();
  rep_.modbus_requests = regs_.requests();
  rep_.cutting = cutting_->report();
  if (regenerative_) rep_.regenerative_cut = regenerative_->report();
  if (dwell_campaigns_) rep_.pose_dwells = dwell_campaigns_->finish();
  for (const auto& [dir, test] : modal_tests_) {
    rep_.measure_records += test->records();
    std::filesystem::create_directories(dir);
    for (const std::string& f : test->write_frf_csvs(dir))
      rep_.measure_files.push_back(dir == o_.measure_out ? f
                                                         : std::filesystem::path(dir).filename().string() + "/" + f);
    spdlog::info("robodamp plant: {} of {} impact records; FRFs written to {}", test->records(),
                 test->records_planned(), dir);
  }
  if (campaign_ && campaign_->started()) open_loop_reference();
  return std::move(rep_);
}

// The impact campaign's records against the same schedule with the amplifier off (the open-loop
// reference, in process): each FRF's peak open and closed.
void PlantEmulator::open_loop_reference() {
  rep_.records = campaign_->records();
  rep_.closed_receptance = campaign_->receptance();
  sim::Plant open = make_plant(cfg_, model_);
  analysis::ImpactCampaign ref(cfg_, open, test_);
  ref.start(rep_.campaign_start_s);
  for (std::size_t k = 0; k < ref.end_tick(); ++k) {
    ref.before_step(k);
    (void)open.sense();  // the control sensor's noise stream advances as in the closed-loop run
    open.step(0.0);
    ref.after_step(k);
  }
  rep_.open_receptance = ref.receptance();
  if (rep_.records == 0) return;
  const double lo = cfg_.analysis.band_min_hz, hi = cfg_.analysis.band_max_hz;
  for (const auto& f : cfg_.robot.frfs) {
    if (f.excitation_location != impact_id_) continue;
    const std::size_t resp = model_.index_of(f.response_location);
    const auto op = analysis::measured_peak(rep_.open_receptance[resp], lo, hi);
    const auto cl = analysis::measured_peak(rep_.closed_receptance[resp], lo, hi);
    rep_.frfs.push_back({f.name, op.magnitude_m_per_n, op.freq_hz, cl.magnitude_m_per_n, cl.freq_hz,
                         (op.magnitude_m_per_n / cl.magnitude_m_per_n - 1.0) * 100.0,
                         std::min(op.coherence_min, cl.coherence_min)});
  }
}

}  // namespace robodamp::hil::detail
