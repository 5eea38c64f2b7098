// The controller's command after an impact, predicted from the discrete loop that runs (docs/tuning.md,
// "Actuator limits"): V(z) = q(z) A_sh(z) F(z) / (1 - q(z) A_sv(z)) on the grid of a long record, F the
// held force samples of sim::ImpactHammer's half-sine (the bench's hammer), back to time by an inverse FFT.
// Its largest |V|, coil force T |V| and slew against the actuator's and amplifier's limits tell whether a
// candidate controller would saturate at that impact, before any time-domain run. Linear: it predicts the
// command the limits would clip, not what happens after they do. Off the real-time path.
#pragma once

#include <complex>
#include <cstddef>
#include <vector>

#include "analysis/fft.hpp"
#include "analysis/loop_model.hpp"

namespace robodamp::analysis {

struct CommandPeak {
  double voltage_v{0.0};      // largest |V|
  double coil_force_n{0.0};   // T |V|, the force the actuator's limit acts on
  double slew_v_per_s{0.0};   // largest |V[k] - V[k-1]| x loop rate
  std::size_t location{0};    // the impact location (index) with the largest voltage
  double time_s{0.0};         // when, after that hit
  double tail_fraction{0.0};  // largest |V| in the record's last tenth / the peak (a loop still ringing)
};

class ImpactCommand {
 public:
  // The plant's responses on the grid come from `plant` (any loop model of the same plant and loop rate:
  // its chain does not enter). The hammer hits every location in turn at t = 0 with peak_n over duration_s.
  // samples: the record, a power of two (2^16 at 5 kHz = 13 s, long enough for a damped loop to ring down).
  ImpactCommand(const LoopModel& plant, double peak_n, double duration_s, std::size_t samples = std::size_t{1} << 16);

  // For the loop m (the same plant, its own chain) at the gain and polarity. One object per thread.
  [[nodiscard]] CommandPeak peak(const LoopModel& m, double gain_ns_per_m, int polarity);

 private:
  double fs_;
  std::size_t locations_;
  std::vector<PlantResponse> responses_;     // per bin from 1 (DC carries no command)
  std::vector<std::complex<double>> force_;  // per bin: the DFT of the held force samples
  RealInverseFft inverse_;
};

}  // namespace robodamp::analysis
