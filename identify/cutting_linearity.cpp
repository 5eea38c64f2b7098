// Whether the mean forces are linear in the feed (identify/cutting_coefficients.hpp, check_linearity).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Dense>

#include "identify/cutting_coefficients.hpp"
#include "identify/regression.hpp"

namespace robodamp::identify {

namespace {

double force(const MeanForces& s, int axis) { return axis == 0 ? s.fx_n : axis == 1 ? s.fy_n : s.fz_n; }

struct Curvature {
  bool significant{false};
  double r2{1.0};
  std::vector<double> residuals;
};

// The line and the quadratic through one axis's forces against the feed.
Curvature curvature(const std::vector<MeanForces>& s, int axis) {
  const auto n = static_cast<Eigen::Index>(s.size());
  Eigen::MatrixXd line(n, 2), quad(n, 3);
  Eigen::VectorXd y(n);
  double peak = 0.0;
  for (Eigen::Index r = 0; r < n; ++r) {
    const double c = s[static_cast<std::size_t>(r)].feed_per_tooth_mm;
    line.row(r) << 1.0, c;
    quad.row(r) << 1.0, c, c * c;
    y(r) = force(s[static_cast<std::size_t>(r)], axis);
    peak = std::max(peak, std::abs(y(r)));
  }
  Curvature out;
  const Regression l = least_squares(line, y);
  out.r2 = l.tss > 0.0 ? 1.0 - l.rss / l.tss : 1.0;
  const Eigen::VectorXd fitted = line * l.theta;
  for (Eigen::Index r = 0; r < n; ++r) out.residuals.push_back(y(r) - fitted(r));
  if (n < 4) return out;
  const Regression q = least_squares(quad, y);
  double moved = 0.0;
  const Eigen::VectorXd qf = quad * q.theta;
  for (Eigen::Index r = 0; r < n; ++r) moved = std::max(moved, std::abs(qf(r) - fitted(r)));
  out.significant = std::abs(q.theta(2)) > q.ci95(2) && moved > 0.01 * peak;
  return out;
}

std::string interval(const char* name, const Estimate& e, const char* unit) {
  char b[96];
  std::snprintf(b, sizeof b, "%s %.4g +- %.2g %s", name, e.value, e.ci95, unit);
  return b;
}

std::string coefficients(const CuttingFit& f, int axis) {
  if (axis == 2) return interval("Kac", f.kac, "N/mm^2") + ", " + interval("Kae", f.kae, "N/mm");
  return interval("Ktc", f.ktc, "N/mm^2") + ", " + interval("Krc", f.krc, "N/mm^2") + ", " +
         interval("Kte", f.kte, "N/mm") + ", " + interval("Kre", f.kre, "N/mm");
}

}  // namespace

std::vector<LinearityCheck> check_linearity(const std::vector<MeanForces>& samples_in, const CuttingTest& test,
                                            const CuttingFit& fit) {
  std::vector<MeanForces> s = samples_in;
  std::sort(s.begin(), s.end(),
            [](const MeanForces& a, const MeanForces& b) { return a.feed_per_tooth_mm < b.feed_per_tooth_mm; });
  std::vector<LinearityCheck> out;
  for (int axis = 0; axis < 3; ++axis) {
    LinearityCheck c;
    c.axis = "xyz"[axis];
    const Curvature all = curvature(s, axis);
    c.r2 = all.r2;
    for (std::size_t i = 0; i < s.size(); ++i) c.residuals_n.emplace_back(s[i].feed_per_tooth_mm, all.residuals[i]);
    c.linear = !all.significant;
    c.linear_up_to_mm = s.back().feed_per_tooth_mm;
    if (!c.linear) {
      // The lowest feeds that fit a line: drop the highest until the curvature is not significant.
      std::size_t m = s.size() - 1;
      for (; m >= 4; --m)
        if (!curvature({s.begin(), s.begin() + static_cast<long>(m)}, axis).significant) break;
      c.linear_up_to_mm = s[m - 1].feed_per_tooth_mm;
      try {
        c.linear_range_fit = identify_cutting({s.begin(), s.begin() + static_cast<long>(m)}, test);
      } catch (const std::invalid_argument&) {
        c.linear_range_fit.reset();
      }
      char head[160];
      std::snprintf(
          head, sizeof head,
          "F%c is not linear in the feed (R^2 %.3f; its curvature is significant at 95 %%): measured minus the line",
          c.axis, c.r2);
      c.message = head;
      for (const auto& [feed, r] : c.residuals_n) {
        char b[48];
        std::snprintf(b, sizeof b, " %.4g mm: %+.3g N,", feed, r);
        c.message += b;
      }
      c.message.back() = '.';
      c.message += " The model's force is linear in the feed, so the coefficients from F" + std::string(1, c.axis) +
                   " carry a model error their 95 % intervals do not hold (all feeds: " + coefficients(fit, axis) +
                   ").";
      char range[96];
      std::snprintf(range, sizeof range, " Over the feeds up to %.4g mm (%zu of %zu", c.linear_up_to_mm, m, s.size());
      c.message += range;
      c.message += m >= 4 ? ", linear): " : ", too few to test their linearity): ";
      c.message +=
          c.linear_range_fit ? coefficients(*c.linear_range_fit, axis) : std::string("too few or too close to fit");
      c.message += ". Fit over the linear range (fewer feeds) or model the chip-thickness dependence.";
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace robodamp::identify
