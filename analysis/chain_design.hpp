// The DVF chain of Eq. 8 designed from configuration, off the real-time path: each configured block as
// an analog transfer function and its digital realisation at the loop rate.
#pragma once

#include <string>
#include <vector>

#include "config/config.hpp"
#include "control/controller_params.hpp"
#include "filters/design.hpp"
#include "filters/transfer_function.hpp"

namespace robodamp::analysis {

struct ChainBlock {
  std::string name;
  config::BlockKind kind;
  filters::TransferFunction analog;
  double prewarp_hz{0.0};
  std::size_t group{0};  // index into ChainDesign::groups
};

// Blocks realised together as one set of sections. The integrator is always realised with the first
// high-pass: 1/s * s^2/D(s) = s/D(s) exactly, so no section has a pole at z = 1 and a constant sensor
// offset gives a bounded (decaying) output; the pair's response is the ideal one, there is no leak error.
struct RealisedGroup {
  std::string label;
  std::vector<std::size_t> blocks;
  filters::TransferFunction analog;
  filters::DigitalDesign digital;
};

struct ChainDesign {
  std::string source;
  std::vector<ChainBlock> blocks;  // in configured order
  std::vector<RealisedGroup> groups;
  double match_freq_hz{0.0};         // default pre-warp of compensators
  control::ControllerParams params;  // what the real-time controller runs

  // Responses of the filter blocks only (accel in, shaped velocity out; no K, polarity, 1/T).
  [[nodiscard]] filters::Complex filters_analog(double f_hz) const;
  [[nodiscard]] filters::Complex filters_digital(double f_hz) const;
  // Whole chain, volts per m/s^2 at the configured K: K * polarity / T * filters.
  [[nodiscard]] filters::Complex chain_analog(double f_hz) const;
  [[nodiscard]] filters::Complex chain_digital(double f_hz) const;
  // One block's digital response as realised: its own sections, or for a block realised with another,
  // the exact bilinear image of the block alone at the group's pre-warp (their product is the group).
  [[nodiscard]] filters::Complex block_digital(std::size_t i, double f_hz) const;
};

// Throws config::ConfigError naming the block (key, line) for a design that cannot run.
[[nodiscard]] ChainDesign design_chain(const config::Config& cfg);

}  // namespace robodamp::analysis
