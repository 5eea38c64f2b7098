// Modes common to several FRFs of one structure (docs/identification.md, "Close modes"): one LSCF with a
// common denominator over all of them (the poly-reference idea: every FRF of a structure has the same
// poles, only the residues differ), so two modes that one FRF shows as a single peak are separated where
// another FRF shows them apart (a close pair of opposite sign at one location). The stabilisation diagram
// and the poles are common; each FRF then gets its residues by LSFD and its own refinement.
#pragma once

#include <vector>

#include "identify/modal_fit.hpp"

namespace robodamp::identify {

// One fit per FRF, in order, with the common poles (each FRF's diagram is the common one). Throws
// std::invalid_argument as fit_modes does, and for a band too wide for one LSCF (fit them one by one).
[[nodiscard]] std::vector<ModalFit> fit_modes_common(const std::vector<FrfData>& frfs, const ModalFitSettings& s);

}  // namespace robodamp::identify
