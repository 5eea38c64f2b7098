#include "milling/cut_stability.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace robodamp::milling {

CutOutcome classify(CutRecord record, const CutSettings& s) {
  CutOutcome o;
  o.record = std::move(record);
  bool per_revolution = !s.pitch_deg.empty();  // with runout or uneven pitch the cut repeats once per revolution
  for (double r : s.runout_um) per_revolution = per_revolution || r != 0.0;
  const CutRecord& r = o.record;
  o.verdict = detect_chatter({&r.x_m, &r.y_m}, r.settle_steps, r.steps_per_tooth * (per_revolution ? r.teeth : 1), 1,
                             1.0 / r.step_s, r.out_of_cut_share());
  return o;
}

CutOutcome run_cut(const std::vector<CutterModalTerm>& terms, const Cutter& cutter, const config::MaterialConfig& mat,
                   const CutSettings& s) {
  return classify(simulate_cut(terms, cutter, mat, s), s);
}

CutOutcome run_cut(CutDynamics& dynamics, const Cutter& cutter, const config::MaterialConfig& mat,
                   const CutSettings& s) {
  return classify(simulate_cut(dynamics, cutter, mat, s), s);
}

CriticalDepth critical_depth(const std::vector<CutterModalTerm>& terms, const Cutter& cutter,
                             const config::MaterialConfig& mat, CutSettings s, double guess_mm, double rel_tol,
                             const std::function<void(const std::string&)>& progress) {
  const double h = 60.0 / (s.rpm * cutter.teeth) / s.steps_per_tooth;
  return critical_depth([&] { return std::make_unique<ToolDynamics>(terms, h); }, cutter, mat, s, guess_mm, rel_tol,
                        progress);
}

CriticalDepth critical_depth(const DynamicsFactory& dynamics, const Cutter& cutter, const config::MaterialConfig& mat,
                             CutSettings s, double guess_mm, double rel_tol,
                             const std::function<void(const std::string&)>& progress) {
  if (!(guess_mm > 0.0)) throw std::invalid_argument("critical_depth: the first guess must be > 0 mm");
  CriticalDepth c;
  auto trial = [&](double depth_mm) {
    s.cut.axial_mm = depth_mm;
    const std::unique_ptr<CutDynamics> dyn = dynamics();
    const CutOutcome o = run_cut(*dyn, cutter, mat, s);
    ++c.simulations;
    if (progress) {
      std::ostringstream os;
      os << "  depth " << depth_mm << " mm: " << to_string(o.verdict.classification);
      if (!o.verdict.stable) os << " at " << o.verdict.chatter_hz << " Hz";
      progress(os.str());
    }
    return o.verdict;
  };
  double lo = 0.0, hi = 0.0;
  ChatterVerdict above;
  const ChatterVerdict first = trial(guess_mm);
  if (first.stable) {
    // First 5 % above the guess, then doubling: stability need not be monotone in depth (a flip island of a
    // low-immersion cut sits between stable depths), and a guess from the accurate method lies at the
    // lowest boundary, which one doubling would step over.
    lo = guess_mm;
    for (hi = 1.05 * guess_mm; c.simulations < 12; hi *= hi < 1.1 * guess_mm ? 2.0 / 1.05 : 2.0) {
      above = trial(hi);
      if (!above.stable) break;
      lo = hi;
    }
    if (above.stable) throw std::runtime_error("critical_depth: stable up to " + std::to_string(hi) + " mm");
  } else {
    hi = guess_mm, above = first;
    for (lo = 0.5 * guess_mm; c.simulations < 24; lo *= 0.5) {
      const ChatterVerdict v = trial(lo);
      if (v.stable) break;
      hi = lo, above = v;
    }
  }
  while (hi - lo > rel_tol * hi) {
    const double mid = 0.5 * (lo + hi);
    const ChatterVerdict v = trial(mid);
    if (v.stable) {
      lo = mid;
    } else {
      hi = mid, above = v;
    }
  }
  c.depth_mm = lo;
  c.above = above.classification;
  c.mechanism = above.mechanism;
  c.chatter_hz = above.chatter_hz;
  return c;
}

}  // namespace robodamp::milling
