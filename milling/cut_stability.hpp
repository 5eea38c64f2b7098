// Whether a simulated cut chatters, and the time-domain critical depth at a speed by bisection on the
// axial depth with the chatter detector's verdict (docs/milling.md, "Time domain"). Off the real-time path.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "milling/chatter.hpp"
#include "milling/cut_simulation.hpp"

namespace robodamp::milling {

struct CutOutcome {
  CutRecord record;
  ChatterVerdict verdict;
};

// The chatter detector's verdict on a cut's record (both displacement components after settling; with
// runout or uneven pitch the cut repeats once per revolution, else once per tooth period).
[[nodiscard]] CutOutcome classify(CutRecord record, const CutSettings& settings);
// Simulates and classifies one cut (the signals: both displacement components after settling).
[[nodiscard]] CutOutcome run_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                                 const config::MaterialConfig& material, const CutSettings& settings);
[[nodiscard]] CutOutcome run_cut(CutDynamics& dynamics, const Cutter& cutter, const config::MaterialConfig& material,
                                 const CutSettings& settings);
// Fresh dynamics for each simulated cut (a bisection runs many).
using DynamicsFactory = std::function<std::unique_ptr<CutDynamics>()>;

struct CriticalDepth {
  double depth_mm{0.0};                 // largest stable depth found (within rel_tol of the smallest unstable one)
  CutClass above{CutClass::kStable};    // what the cut does just above it
  CutClass mechanism{CutClass::kHopf};  // Hopf or flip there
  double chatter_hz{0.0};               // there
  int simulations{0};
};

// Bisection from a first guess (e.g. the zero-order limit): raised 5 % and then doubled, or halved, until
// the verdict changes, then halved to rel_tol: the boundary just above a stable guess (stability need not
// be monotone in depth: flip islands). progress (optional) gets one line per simulation.
[[nodiscard]] CriticalDepth critical_depth(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                                           const config::MaterialConfig& material, CutSettings settings,
                                           double guess_mm, double rel_tol = 2e-3,
                                           const std::function<void(const std::string&)>& progress = {});
[[nodiscard]] CriticalDepth critical_depth(const DynamicsFactory& dynamics, const Cutter& cutter,
                                           const config::MaterialConfig& material, CutSettings settings,
                                           double guess_mm, double rel_tol = 2e-3,
                                           const std::function<void(const std::string&)>& progress = {});

}  // namespace robodamp::milling
