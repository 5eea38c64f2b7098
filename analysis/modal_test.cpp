#include "analysis/modal_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace robodamp::analysis {

namespace {
constexpr double kMaxGapS = 1.0;  // ImpactCampaign: each hit after a seeded gap of up to 1 s
constexpr double kTailS = 1.0;    // after the last record
constexpr int kAmplitudeGrid = 2000;
}  // namespace

CommissioningPlan commissioning_plan(const config::Config& cfg, const sim::PlantModel& model) {
  const auto& c = cfg.commissioning;
  CommissioningPlan p;
  p.chirp_start_s = c.settle_s;
  p.chirp_end_s = c.settle_s + c.chirp_period_s * c.chirp_periods;
  double peak_n_per_v = 0.0;
  for (int i = 0; i <= kAmplitudeGrid; ++i) {
    const double f = c.chirp_f0_hz + (c.chirp_f1_hz - c.chirp_f0_hz) * i / kAmplitudeGrid;
    peak_n_per_v = std::max(peak_n_per_v, std::abs(model.actuator.n_per_v(f)));
  }
  const double by_force = c.chirp_force_fraction * model.actuator.force_limit_n / peak_n_per_v;
  const double by_voltage = c.chirp_force_fraction * model.voltage_limit_v;
  p.chirp_amplitude_v = std::min(by_force, by_voltage);
  p.predicted_peak_force_n = p.chirp_amplitude_v * peak_n_per_v;
  double t = p.chirp_end_s + c.quiet_s;
  const double per_location = c.impacts_per_location * (c.record_s + kMaxGapS);
  for (std::size_t l = 0; l < model.locations.size(); ++l) {
    p.impacts_start_s.push_back(t);
    t += per_location;
  }
  p.duration_s = t + kTailS;
  return p;
}

std::string frf_file_name(int response_id, int excitation_id) {
  return "frf_" + std::to_string(response_id) + "_" + std::to_string(excitation_id) + ".csv";
}

ModalTest::ModalTest(const config::Config& cfg, sim::Plant& plant, const CommissioningPlan& plan)
    : cfg_(cfg), model_(plant.model()) {
  cfg_.bench.averages = cfg.commissioning.impacts_per_location;
  cfg_.bench.record_s = cfg.commissioning.record_s;
  for (std::size_t l = 0; l < model_.locations.size(); ++l) {
    const ImpactTest test{l, cfg_.bench.impact_peak_n, cfg_.bench.impact_duration_ms, false, 0.0, 1};
    campaigns_.push_back(std::make_unique<ImpactCampaign>(cfg_, plant, test));
    campaigns_.back()->start(plan.impacts_start_s.at(l));
  }
}

void ModalTest::before_step(std::size_t k) noexcept {
  for (auto& c : campaigns_) c->before_step(k);
}

void ModalTest::after_step(std::size_t k) noexcept {
  for (auto& c : campaigns_) c->after_step(k);
}

bool ModalTest::done(std::size_t k) const {
  return std::all_of(campaigns_.begin(), campaigns_.end(), [k](const auto& c) { return c->done(k); });
}

int ModalTest::records() const {
  int n = 0;
  for (const auto& c : campaigns_) n += c->records();
  return n;
}

int ModalTest::records_planned() const { return static_cast<int>(campaigns_.size()) * cfg_.bench.averages; }

std::vector<std::vector<FrfEstimate>> ModalTest::receptance() const {
  std::vector<std::vector<FrfEstimate>> out;
  for (const auto& c : campaigns_) out.push_back(c->receptance());
  return out;
}

std::vector<std::string> ModalTest::write_frf_csvs(const std::string& dir) const {
  std::filesystem::create_directories(dir);
  std::vector<std::string> names;
  const auto all = receptance();
  for (std::size_t h = 0; h < all.size(); ++h) {
    for (std::size_t g = 0; g < all[h].size(); ++g) {
      const FrfEstimate& e = all[h][g];
      const std::string name = frf_file_name(model_.locations[g].id, model_.locations[h].id);
      const std::string path = (std::filesystem::path(dir) / name).string();
      std::FILE* f = std::fopen(path.c_str(), "w");
      if (f == nullptr) throw std::runtime_error("cannot write " + path);
      std::fprintf(f, "freq_hz,re_m_per_n,im_m_per_n,coherence\n");
      for (std::size_t i = 0; i < e.f_hz.size(); ++i) {
        if (e.f_hz[i] <= 0.0) continue;
        std::fprintf(f, "%.9g,%.10g,%.10g,%.6f\n", e.f_hz[i], e.h1[i].real(), e.h1[i].imag(), e.coherence[i]);
      }
      if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
      names.push_back(name);
    }
  }
  return names;
}

}  // namespace robodamp::analysis
