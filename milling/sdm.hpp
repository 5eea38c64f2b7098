// Stability of the milling process by first-order semi-discretization (Insperger and Stepan 2004;
// docs/milling.md, "Semi-discretization"). The open-loop structure's modal state space (cutter frame,
// milling/tool_dynamics.hpp) with the linearised regenerative force
//   x' = A x + B M(t) (q(t) - q(t - tau)),  q = C x,
// M(t) the tooth-periodic directional matrix summed over the engaged teeth and axial slices (helix lag
// and ball end as in the frequency-domain and time-domain models). Over each of m intervals of the tooth
// period, M is its interval mean and the delayed q is interpolated linearly between samples; the exact
// solution of each interval gives the monodromy matrix over one period, whose largest eigenvalue decides:
// stable below 1 in magnitude; crossing -1 (period doubling, flip) or as a complex pair (Hopf).
// Off the real-time path.
#pragma once

#include <complex>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "milling/chatter.hpp"
#include "milling/cutting.hpp"
#include "milling/interval_collocation.hpp"
#include "milling/tool_dynamics.hpp"

namespace robodamp::milling {

// The directional matrix of the linearised regenerative force, F = M (q(t - tau) - q(t)) with M in N/m,
// summed over the engaged teeth and the axial slices of a cut at one depth (helix lag and ball end as in
// the frequency-domain and time-domain models).
class DirectionalMatrix {
 public:
  DirectionalMatrix(const Cutter& cutter, const config::MaterialConfig& material, config::MillingMode mode,
                    double radial_mm, int axial_slices, double axial_mm);
  // Mean over the spindle angles [phi0, phi0 + dphi) by the midpoint rule on `sub` sub-intervals (the
  // engagement switches inside), N/m.
  [[nodiscard]] Eigen::Matrix2d mean(double phi0_rad, double dphi_rad, int sub) const;

 private:
  struct ToothOffset {
    double rad, sin, cos;  // a tooth's angle behind the spindle's, with the slice's helix lag
  };
  struct EngagedSlice {
    Slice slice;
    Engagement engagement;
    double sin_kappa;
    std::vector<ToothOffset> teeth;
  };
  std::vector<EngagedSlice> slices_;
  int teeth_;
  double kt_, kr_;
};

// The smallest unstable depth near a first guess from ln|mu(depth)| (< 0 stable): bracketed by steps from the
// guess (the first `first_step`, each next the square of the last, at most kBracketStep = 1.6), then the
// Illinois method (regula falsi halving the stale end's weight; bisection while the bracket is wide) to
// hi - lo <= rel_tol hi. lo is stable, hi unstable; hi = inf when stable up to 1 m. A guess known to be close
// (a neighbouring speed's answer) takes a small first step and a narrow bracket.
// Throws std::runtime_error when unstable down to 1 nm.
inline constexpr double kBracketStep = 1.6;
struct DepthBracket {
  double lo_mm{0.0}, hi_mm{0.0};
};
[[nodiscard]] DepthBracket find_critical_depth(const std::function<double(double)>& ln_mu, double guess_mm,
                                               double rel_tol, double first_step = kBracketStep);

// The chatter frequency of a Floquet mode q(t) = mu^(t/T) p(t), p periodic, from its displacement at times
// t_periods (in tooth periods, over one period) as [x, y] pairs: p's strongest harmonic m gives the
// frequency |arg mu / 2 pi + m| / T, the physically right one of the aliases the multiplier allows.
[[nodiscard]] double floquet_chatter_hz(std::complex<double> mu, const std::vector<double>& t_periods,
                                        const Eigen::VectorXcd& history, double tooth_hz);

struct SdmPoint {
  double rpm{0.0};
  double critical_depth_mm{0.0};
  CutClass type{CutClass::kHopf};  // how it loses stability there: kHopf or kFlip
  double chatter_hz{0.0};          // from the critical multiplier's angle, nearest the structure's modes
};

class SdmModel {
 public:
  SdmModel(const std::vector<CutterModalTerm>& terms, const Cutter& cutter, const config::MaterialConfig& material,
           config::MillingMode mode, double radial_mm, int axial_slices, int steps_per_period);

  // The largest-magnitude eigenvalue of the monodromy matrix at this depth and speed.
  [[nodiscard]] std::complex<double> multiplier(double axial_mm, double rpm) const;
  // The same with the critical eigenvector's chatter frequency (floquet_chatter_hz).
  [[nodiscard]] std::complex<double> multiplier(double axial_mm, double rpm, double* chatter_hz) const;
  // Critical depth by bisection, starting from a guess (e.g. the zero-order limit).
  [[nodiscard]] SdmPoint critical(double rpm, double guess_mm, double rel_tol = 1e-3,
                                  double first_step = kBracketStep) const;
  [[nodiscard]] int steps_per_period() const { return m_; }
  // Every cutting interval by its dense exponential (milling/interval_exp.hpp), never by the low-rank
  // collocation (milling/interval_collocation.hpp) a many-mode structure's short intervals take otherwise:
  // the reference the tests compare with.
  void dense_intervals_only() { low_rank_ = false; }

 private:
  // The collocations a search at one speed has made, by their node counts: their tables depend on the interval
  // alone, so the search's depths share them (the same arithmetic as making them again).
  struct Collocations {
    double h{0.0};
    std::map<int, IntervalCollocation> by_nodes;
  };
  // The monodromy matrix over one tooth period (kept: a search's collocations); its dominant eigenvalue (and
  // chatter frequency).
  [[nodiscard]] Eigen::MatrixXd monodromy(double axial_mm, double rpm, Collocations* kept = nullptr) const;
  [[nodiscard]] std::complex<double> dominant(const Eigen::MatrixXd& z, double rpm, double* chatter_hz) const;
  // The chatter frequency of z's Floquet mode for its multiplier mu (the eigenvector by inverse iteration).
  [[nodiscard]] double chatter_hz_of(const Eigen::MatrixXd& z, std::complex<double> mu, double rpm) const;
  // Each interval's mean directional matrix at this depth (N/m).
  [[nodiscard]] std::vector<Eigen::Matrix2d> directional_means(double axial_mm) const;
  // The nodes of the collocation for intervals of length h where it is cheaper than the dense exponential;
  // 0: the dense exponential.
  [[nodiscard]] int collocation_nodes(const std::vector<Eigen::Matrix2d>& cut, double h) const;

  Eigen::MatrixXd a_, b_, c_;            // modes' states as (wn q, q'), A block diagonal
  std::vector<Eigen::Matrix2d> blocks_;  // A's blocks
  Cutter cutter_;
  config::MaterialConfig material_;
  config::MillingMode mode_;
  double radial_mm_;
  int slices_, m_;
  bool low_rank_{true};
};

}  // namespace robodamp::milling
