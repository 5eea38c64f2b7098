// The steps of the modal fit (identify/modal_fit.hpp), shared by the single-FRF fit and the common-pole fit
// over several FRFs (identify/common_pole_fit.hpp). Not a public interface.
#pragma once

#include <cmath>
#include <complex>
#include <functional>
#include <vector>

#include "identify/modal_fit.hpp"
#include "units/units.hpp"

namespace robodamp::identify::detail {

struct Pole {
  Complex s;  // rad/s
  [[nodiscard]] double freq_hz() const { return std::abs(s) / kTwoPi; }
  [[nodiscard]] double damping() const { return -s.real() / std::abs(s); }
};

// The points a fit uses: finite (else std::invalid_argument naming the row), in the band, coherent.
void usable_points(const FrfData& d, const ModalFitSettings& s, std::vector<double>& f, std::vector<Complex>& h);
// LSCF poles at order p within [f_lo, f_hi].
[[nodiscard]] std::vector<Pole> lscf_poles(const std::vector<double>& f, const std::vector<Complex>& h, int p,
                                           double dt, double f_lo, double f_hi);
// A column of the diagram whose damping scatters more than ModalFitSettings::stable_damping allows but less
// than this (relative, order to order) while its frequency holds is a candidate mode ...
inline constexpr double kLooseStableDamping = 0.25;
// ... kept only when it brings the fit's error below this share of the error without it (noise does not).
inline constexpr double kCandidateErrorRatio = 0.8;

struct PoleSelection {
  std::vector<Pole> stable;      // stable at the highest order (frequency and damping)
  std::vector<Pole> candidates;  // stable in frequency, damping within kLooseStableDamping, not one of `stable`
};

// The stabilisation diagram over orders 2..max_order (into `diagram`) and the poles stable at the highest.
// Throws std::invalid_argument when none is.
[[nodiscard]] PoleSelection stable_poles(const std::function<std::vector<Pole>(int)>& poles_at_order,
                                         const ModalFitSettings& s, std::vector<StabilisationPoint>& diagram);
// The stable poles and each candidate whose addition lowers fit_error (of the poles, sorted by frequency)
// below kCandidateErrorRatio times the error without it.
[[nodiscard]] std::vector<Pole> with_supported_candidates(
    const PoleSelection& selection, const std::function<double(const std::vector<Pole>&)>& fit_error);
// LSFD residues of the poles with residual terms; weight_floor > 0 weighs rows to relative error.
void lsfd(const std::vector<double>& f, const std::vector<Complex>& h, const std::vector<Pole>& poles, ModalFit& fit,
          double weight_floor = 0.0);
// Levenberg-Marquardt over every mode's frequency, damping and residue; kept only while physical.
void refine(const std::vector<double>& f, const std::vector<Complex>& h, ModalFit& fit);

}  // namespace robodamp::identify::detail
