#include "analysis/mode_improvement.hpp"

#include <algorithm>
#include <cmath>

namespace robodamp::analysis {

std::vector<ModeImprovement> mode_improvements(const LoopModel& m, double gain_ns_per_m, int polarity) {
  std::vector<ModeImprovement> out;
  const config::Config& cfg = m.config();
  if (cfg.robot.frfs.empty() || !m.stable(gain_ns_per_m, polarity)) return out;
  const auto& frf = cfg.robot.frfs.front();
  const std::size_t g = m.plant().index_of(frf.response_location), h = m.plant().index_of(frf.excitation_location);
  for (const auto& mode : frf.modes) {
    ModeImprovement mi;
    mi.freq_hz = mode.natural_freq_hz;
    for (double f = 0.9 * mi.freq_hz; f <= 1.1 * mi.freq_hz; f += 0.005 * mi.freq_hz) {
      const PlantResponse p = m.plant_response(f);
      mi.open_peak_m_per_n = std::max(mi.open_peak_m_per_n, std::abs(m.open_discrete(p, g, h)));
      mi.closed_peak_m_per_n =
          std::max(mi.closed_peak_m_per_n,
                   std::abs(m.closed_discrete(p, m.chain_filters_digital(f), g, h, gain_ns_per_m, polarity)));
    }
    mi.improvement_pct = 100.0 * (mi.open_peak_m_per_n / mi.closed_peak_m_per_n - 1.0);
    out.push_back(mi);
  }
  return out;
}

std::optional<ModeImprovement> worst_mode(const std::vector<ModeImprovement>& modes, double min_hz, double max_hz,
                                          bool inside) {
  std::optional<ModeImprovement> out;
  for (const ModeImprovement& mi : modes)
    if ((mi.freq_hz >= min_hz && mi.freq_hz <= max_hz) == inside && (!out || mi.improvement_pct < out->improvement_pct))
      out = mi;
  return out;
}

bool BandWorst::add(const std::vector<ModeImprovement>& modes, double min_hz, double max_hz) {
  const auto out = worst_mode(modes, min_hz, max_hz, false);
  if (out && (!outside || out->improvement_pct < outside->improvement_pct)) outside = out;
  const auto in = worst_mode(modes, min_hz, max_hz, true);
  if (!in || (inside && in->improvement_pct >= inside->improvement_pct)) return false;
  inside = in;
  return true;
}

}  // namespace robodamp::analysis
