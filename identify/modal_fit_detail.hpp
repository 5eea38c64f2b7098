// The steps of the modal fit (identify/modal_fit.hpp), shared by the single-FRF fit and the common-pole fit
// over several FRFs (identify/common_pole_fit.hpp). Not a public interface.
#pragma once

#include <cmath>
#include <complex>
#include <functional>
#include <vector>

#include "identify/modal_fit.hpp"

namespace robodamp::identify::detail {

inline constexpr double kTwoPi = 2.0 * M_PI;

struct Pole {
  Complex s;  // rad/s
  [[nodiscard]] double freq_hz() const { return std::abs(s) / kTwoPi; }
  [[nodiscard]] double damping() const { return -s.real() / std::abs(s); }
};

// The points a fit uses: finite (else std::invalid_argument naming the row), in the band, coherent.
void usable_points(const FrfData& d, const ModalFitSettings& s, std::vector<double>& f, std::vector<Complex>& h);
// LSCF poles at order p within [f_lo, f_hi].
[[nodiscard]] std::vector<Pole> lscf_poles(const std::vector<double>& f, const std::vector<Complex>& h, int p, double dt,
                                           double f_lo, double f_hi);
// The stabilisation diagram over orders 2..max_order (into `diagram`) and the poles stable at the highest.
// Throws std::invalid_argument when none is.
[[nodiscard]] std::vector<Pole> stable_poles(const std::function<std::vector<Pole>(int)>& poles_at_order,
                                             const ModalFitSettings& s, std::vector<StabilisationPoint>& diagram);
// LSFD residues of the poles with residual terms; weight_floor > 0 weighs rows to relative error.
void lsfd(const std::vector<double>& f, const std::vector<Complex>& h, const std::vector<Pole>& poles, ModalFit& fit,
          double weight_floor = 0.0);
// Levenberg-Marquardt over every mode's frequency, damping and residue; kept only while physical.
void refine(const std::vector<double>& f, const std::vector<Complex>& h, ModalFit& fit);

}  // namespace robodamp::identify::detail
