// The regenerative cut, one step at a time (docs/milling.md, "Time domain"): the cutter's axial slices with
// helix lag, per-tooth runout, the linear or exponential force model, and the surface memory per slice and
// angular position that makes the chip from what the previous passes actually left. simulate_cut steps it
// against a structure's dynamics in process; the HIL emulator (hil/regenerative_cut.hpp) against the
// emulated robot that a separate robodamp run controls. The step is the tooth period / steps_per_tooth.
// Built with every buffer it needs (allocates); force() and end_step() do not allocate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "config/milling_config.hpp"
#include "milling/cutting.hpp"

namespace robodamp::milling {

struct CutSettings;

class CutProcess {
 public:
  // Throws std::invalid_argument for rpm <= 0 or steps_per_tooth < 1.
  CutProcess(const Cutter& cutter, const config::MaterialConfig& material, const CutSettings& settings);

  [[nodiscard]] double step_s() const { return step_s_; }
  [[nodiscard]] std::size_t steps_per_revolution() const { return bins_; }

  // The spindle or the depth changed: this process (built with the new speed, depth or step) takes over
  // `before`'s cut after its first `steps` steps. The spindle's angle and the feed travelled carry over;
  // each slice's surface is the one `before` left at the same height and workpiece angle (nearest bin),
  // and a slice above `before`'s depth is fresh material (the nominal chip). Returns the step index this
  // process continues at (force() from it on, in order). Allocation-free; call before the first force().
  std::size_t continue_from(const CutProcess& before, std::size_t steps) noexcept;

  // The mean cutting force on the tool over step k (cutter frame: x = feed, y = wall normal; N) from the
  // tool's displacement at the step's middle (m). The edges that cut renew the surface. With stats (after
  // settling) the engagement, the walls and the revolutions are counted. Steps come in order from 0.
  [[nodiscard]] Eigen::Vector2d force(std::size_t k, const Eigen::Vector2d& q_mid_m, bool stats) noexcept;
  // After step k: the displacement at its start and end, where the edges that passed the wall made it.
  void end_step(const Eigen::Vector2d& q_start_m, const Eigen::Vector2d& q_end_m) noexcept;

  [[nodiscard]] std::uint64_t engaged_samples() const { return engaged_samples_; }
  [[nodiscard]] std::uint64_t out_of_cut_samples() const { return out_of_cut_samples_; }
  // The machined wall per revolution after settling (mean over slices, um; + = undercut).
  [[nodiscard]] const std::vector<double>& wall_per_rev_um() const { return wall_per_rev_um_; }
  // Per slice (tip first), NaN where the slice does not reach the wall; and their mean over the slices.
  [[nodiscard]] std::vector<double> wall_um() const;
  [[nodiscard]] double sle_um() const;

 private:
  // One axial slice: its geometry on its own angular grid (bin i is the angle i dphi - lag, where the
  // slice's edge of some tooth sits at every step), and the surface its passes left.
  struct SliceState {
    double z_m{0.0}, height_m{0.0}, radius_m{0.0};
    double lag_rad{0.0};
    double sk{1.0};                        // sin(kappa)
    std::vector<double> sin_phi, cos_phi;  // at the middle of the bin's step
    std::vector<double> weight;            // share of the bin's step the edge spends in the engagement
    std::vector<char> in_material;         // weight > 0
    std::vector<double> surface_m;         // radial reach of the last pass that cut, per bin (workpiece frame)
    std::vector<double> surface_feed_m;    // the nominal feed travelled when that pass cut (continue_from)
    std::vector<char> cut_before;
    std::size_t wall_bin{0};    // bin whose step passes the surface-generating angle
    double wall_fraction{0.0};  // where in that step
    double wall_sum_m{0.0};
    int wall_count{0};
    double wall_rev_max_m{-std::numeric_limits<double>::infinity()};
  };
  struct WallPass {
    SliceState* slice;
    double runout_m;
  };
  std::vector<SliceState> slices_;
  int teeth_{0};
  std::size_t bins_{0};
  double step_s_{0.0}, feed_per_tooth_m_{0.0}, wall_angle_rad_{0.0};
  // The nominal feed travelled at the start of step first_step_ (continue_from; 0 and 0 for a fresh cut).
  double feed_origin_m_{0.0};
  std::size_t first_step_{0};
  [[nodiscard]] double feed_at_m(double step) const {
    return feed_origin_m_ + feed_per_tooth_m_ * (step - static_cast<double>(first_step_)) / steps_per_tooth_;
  }
  int steps_per_tooth_{0};
  std::vector<double> runout_m_, pitch_feed_m_;
  std::vector<std::size_t> tooth_bin_;
  double kt_{0.0}, kr_{0.0}, kte_{0.0}, kre_{0.0}, exponent_{0.0}, reference_chip_m_{0.0};
  std::vector<WallPass> walls_;  // this step's
  std::vector<double> wall_per_rev_um_;
  std::uint64_t engaged_samples_{0}, out_of_cut_samples_{0};
};

}  // namespace robodamp::milling
