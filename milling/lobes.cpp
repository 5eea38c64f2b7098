#include "milling/lobes.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace robodamp::milling {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Eigenvalues of a 2x2 complex matrix, closed form.
std::array<Complex, 2> eigenvalues(const Eigen::Matrix2cd& m) {
  const Complex half_trace = 0.5 * (m(0, 0) + m(1, 1));
  const Complex det = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  const Complex root = std::sqrt(half_trace * half_trace - det);
  return {half_trace + root, half_trace - root};
}

}  // namespace

ChatterProcess chatter_process(const config::ToolConfig& tool, const config::MaterialConfig& material,
                               const config::CutConfig& cut) {
  ChatterProcess p;
  p.teeth = tool.teeth;
  p.kt_n_per_m2 = material.kt_n_per_mm2 * 1e6;
  // The 2D zero-order model uses the nominal radius for the immersion, also for a ball end (its
  // engagement shrinks towards the tip; with slotting, as in Tian et al. (2024), the immersion is the same).
  p.alpha = directional_matrix(engagement(0.5 * tool.diameter_mm, cut.radial_mm, cut.mode),
                               material.kr_n_per_mm2 / material.kt_n_per_mm2);
  p.feed_axis = cut.feed_axis;
  return p;
}

LobeModel::LobeModel(const Structure& structure, const ChatterProcess& process, const config::LobesConfig& settings)
    : structure_(structure), process_(process), settings_(settings) {
  // Frequency grid: logarithmic from half the lowest resonance to the limit (default 4x the highest,
  // and at least 4x the tooth-passing frequency at the top speed), plus points_per_mode points
  // across +-5 half-power half-bandwidths of every resonance (the lobes of lightly damped or low modes
  // are narrow in frequency and dense in speed).
  double lo = kInf, hi = 0.0;
  for (const auto& r : structure.resonances()) {
    lo = std::min(lo, r.freq_hz);
    hi = std::max(hi, r.freq_hz);
  }
  if (!std::isfinite(lo)) lo = 1.0, hi = 1000.0;
  lo = std::max(0.05, 0.5 * lo);
  hi = settings.freq_max_hz.value_or(std::max(4.0 * hi, 4.0 * settings.rpm_max / 60.0 * process.teeth));
  const int base = 2000;
  for (int i = 0; i <= base; ++i) grid_hz_.push_back(lo * std::pow(hi / lo, static_cast<double>(i) / base));
  for (const auto& r : structure.resonances()) {
    const double z = std::clamp(r.damping_ratio, 1e-3, 0.5);
    const double a = r.freq_hz * std::max(0.05, 1.0 - 5.0 * z), b = r.freq_hz * (1.0 + 5.0 * z);
    for (int i = 0; i < settings.points_per_mode; ++i) {
      const double f = a + (b - a) * i / (settings.points_per_mode - 1);
      if (f >= lo && f <= hi) grid_hz_.push_back(f);
    }
  }
  std::sort(grid_hz_.begin(), grid_hz_.end());
  grid_hz_.erase(std::unique(grid_hz_.begin(), grid_hz_.end(),
                             [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::abs(y); }),
                 grid_hz_.end());
  auto evaluate_grid = [this] {
    evals_.clear();
    evals_.reserve(grid_hz_.size());
    for (std::size_t i = 0; i < grid_hz_.size(); ++i)
      evals_.push_back(evaluate(grid_hz_[i], i == 0 ? nullptr : &evals_.back()));
  };
  evaluate_grid();
  // Where a branch's b_lim changes sign (the edge of a band that can chatter), eps runs to 0 or 2 pi and
  // the lobes to high speeds: locate each edge and add points approaching it geometrically.
  std::vector<double> extra;
  for (std::size_t i = 0; i + 1 < grid_hz_.size(); ++i) {
    for (int br = 0; br < 2; ++br) {
      const bool v0 = depth_and_phase(evals_[i].lambda[br]).has_value();
      if (v0 == depth_and_phase(evals_[i + 1].lambda[br]).has_value()) continue;
      double valid = v0 ? grid_hz_[i] : grid_hz_[i + 1], invalid = v0 ? grid_hz_[i + 1] : grid_hz_[i];
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (valid + invalid);
        (depth_and_phase(evaluate(mid, &evals_[i]).lambda[br]) ? valid : invalid) = mid;
      }
      const double span = (v0 ? grid_hz_[i] : grid_hz_[i + 1]) - valid;
      for (int k = 1; k <= 24; ++k) extra.push_back(valid + span * std::ldexp(1.0, -k));
      extra.push_back(valid);
    }
  }
  if (!extra.empty()) {
    grid_hz_.insert(grid_hz_.end(), extra.begin(), extra.end());
    std::sort(grid_hz_.begin(), grid_hz_.end());
    grid_hz_.erase(std::unique(grid_hz_.begin(), grid_hz_.end()), grid_hz_.end());
    evaluate_grid();
  }
}

Eigen::Matrix2cd LobeModel::oriented(double f_hz) const {
  return process_.alpha.cast<Complex>() * structure_.frf_cutter(f_hz, process_.feed_axis);
}

LobeModel::Eval LobeModel::evaluate(double f_hz, const Eval* previous) const {
  const Eigen::Matrix2cd phi = oriented(f_hz);
  auto e = eigenvalues(phi);
  // Branch tracking: keep the pairing closest to the previous frequency's eigenvalues.
  if (previous != nullptr) {
    const Complex p0 = -1.0 / previous->lambda[0], p1 = -1.0 / previous->lambda[1];
    auto dist = [](Complex a, Complex b) { return std::isfinite(std::abs(b)) ? std::abs(a - b) : 0.0; };
    if (dist(e[0], p1) + dist(e[1], p0) < dist(e[0], p0) + dist(e[1], p1)) std::swap(e[0], e[1]);
  }
  const double scale = phi.cwiseAbs().maxCoeff();
  Eval out;
  for (int k = 0; k < 2; ++k)
    out.lambda[k] = std::abs(e[static_cast<std::size_t>(k)]) > 1e-12 * scale && scale > 0.0
                        ? -1.0 / e[static_cast<std::size_t>(k)]
                        : Complex(std::numeric_limits<double>::quiet_NaN(), 0.0);
  return out;
}

std::optional<std::pair<double, double>> LobeModel::depth_and_phase(Complex lambda) const {
  if (!std::isfinite(lambda.real()) || !(lambda.real() < 0.0)) return std::nullopt;
  const double kappa = lambda.imag() / lambda.real();
  const double b = -kTwoPi * lambda.real() * (1.0 + kappa * kappa) / (process_.teeth * process_.kt_n_per_m2);
  const double eps = M_PI - 2.0 * std::atan(kappa);
  return std::make_pair(b, eps);
}

double LobeModel::speed_rpm(double f_hz, double eps, int lobe) const {
  return 60.0 * kTwoPi * f_hz / (process_.teeth * (eps + kTwoPi * lobe));
}

std::vector<double> LobeModel::speeds_rpm() const {
  std::vector<double> n(static_cast<std::size_t>(settings_.points));
  const double a = settings_.rpm_min, b = settings_.rpm_max;
  for (int i = 0; i < settings_.points; ++i) {
    const double t = static_cast<double>(i) / (settings_.points - 1);
    n[static_cast<std::size_t>(i)] = settings_.log_spacing ? a * std::pow(b / a, t) : a + (b - a) * t;
  }
  return n;
}

LobeDiagram LobeModel::diagram() const {
  const std::vector<double> speeds = speeds_rpm();
  LobeDiagram d;
  d.frequency_points = grid_hz_.size();
  d.curve.resize(speeds.size());
  for (std::size_t i = 0; i < speeds.size(); ++i) d.curve[i] = {speeds[i], kInf, 0.0, -1, -1};
  const double n_min = settings_.rpm_min, n_max = settings_.rpm_max;
  const double index_scale = settings_.log_spacing ? (settings_.points - 1) / std::log(n_max / n_min)
                                                   : (settings_.points - 1) / (n_max - n_min);
  auto index_of = [&](double n) {
    return settings_.log_spacing ? std::log(n / n_min) * index_scale : (n - n_min) * index_scale;
  };
  // Lobe numbers whose speed at (f, eps) lies within the range, widened by one on each side.
  auto lobe_range = [&](double f, double eps) {
    const double w60 = 60.0 * kTwoPi * f / process_.teeth;
    const int lo = std::max(0, static_cast<int>(std::ceil((w60 / n_max - eps) / kTwoPi)) - 1);
    const int hi = static_cast<int>(std::floor((w60 / n_min - eps) / kTwoPi)) + 1;
    return std::make_pair(lo, std::max(lo, hi));
  };
  for_each_segment([&](int br, std::size_t i, std::pair<double, double> p1, std::pair<double, double> p2) {
    const double f1 = grid_hz_[i], f2 = grid_hz_[i + 1];
    const auto r1 = lobe_range(f1, p1.second), r2 = lobe_range(f2, p2.second);
    for (int j = std::min(r1.first, r2.first); j <= std::max(r1.second, r2.second); ++j) {
      const double n1 = speed_rpm(f1, p1.second, j), n2 = speed_rpm(f2, p2.second, j);
      const double x1 = index_of(std::min(n1, n2)), x2 = index_of(std::max(n1, n2));
      const auto k_lo = static_cast<long>(std::max(0.0, std::ceil(x1)));
      const auto k_hi = static_cast<long>(std::min(static_cast<double>(settings_.points - 1), std::floor(x2)));
      for (long k = k_lo; k <= k_hi; ++k) {
        LobePoint& c = d.curve[static_cast<std::size_t>(k)];
        const double t = n2 != n1 ? (c.rpm - n1) / (n2 - n1) : 0.0;
        const double b = p1.first + t * (p2.first - p1.first);
        if (b < c.b_lim_mm) c = {c.rpm, b, f1 + t * (f2 - f1), j, br};
      }
    }
  });
  d.minimum = {0.0, kInf, 0.0, -1, -1};
  for (const auto& c : d.curve)
    if (c.b_lim_mm < d.minimum.b_lim_mm) d.minimum = c;
  for (auto& c : d.curve) c = in_mm(c);  // found in metres
  d.minimum = in_mm(d.minimum);
  return d;
}

std::optional<LobePoint> LobeModel::limit_at(double rpm) const {
  std::optional<LobePoint> best;
  for_each_segment([&](int br, std::size_t i, std::pair<double, double> p1, std::pair<double, double> p2) {
    const double f1 = grid_hz_[i], f2 = grid_hz_[i + 1];
    const int j_max = static_cast<int>(60.0 * std::max(f1, f2) / (process_.teeth * rpm)) + 1;
    for (int j = 0; j <= j_max; ++j) {
      double fa = f1, fb = f2;
      double ga = speed_rpm(f1, p1.second, j) - rpm, gb = speed_rpm(f2, p2.second, j) - rpm;
      if (ga * gb > 0.0) continue;
      // Bisection on the chatter frequency, the branch followed from the segment's end points.
      const Complex la = evals_[i].lambda[br], lb = evals_[i + 1].lambda[br];
      std::pair<double, double> pm = ga == 0.0 ? p1 : p2;
      double fm = ga == 0.0 ? f1 : f2;
      bool ok = true;
      for (int it = 0; it < 60 && ga != 0.0 && gb != 0.0; ++it) {
        fm = 0.5 * (fa + fb);
        const double t = (fm - f1) / (f2 - f1);
        const Complex guess_eig = -1.0 / (la + t * (lb - la));
        const auto e = eigenvalues(oriented(fm));
        const Complex eig = std::abs(e[0] - guess_eig) <= std::abs(e[1] - guess_eig) ? e[0] : e[1];
        const auto p = depth_and_phase(-1.0 / eig);
        if (!p) {
          ok = false;
          break;
        }
        pm = *p;
        const double gm = speed_rpm(fm, p->second, j) - rpm;
        if (gm * ga <= 0.0)
          fb = fm, gb = gm;
        else
          fa = fm, ga = gm;
        if (fb - fa < 1e-12 * fb) break;
      }
      if (ok && (!best || pm.first < best->b_lim_mm)) best = LobePoint{rpm, pm.first, fm, j, br};
    }
  });
  if (best) best = in_mm(*best);  // found in metres
  return best;
}

std::vector<LobePoint> LobeModel::lobe_points(int lobe) const {
  std::vector<LobePoint> out;
  for (int br = 0; br < 2; ++br)
    for (std::size_t i = 0; i < grid_hz_.size(); ++i)
      if (const auto p = depth_and_phase(evals_[i].lambda[br]))
        out.push_back(in_mm({speed_rpm(grid_hz_[i], p->second, lobe), p->first, grid_hz_[i], lobe, br}));
  return out;
}

LobePoint LobeModel::in_mm(LobePoint metres) {
  metres.b_lim_mm *= kMmPerM;
  return metres;
}

Complex LobeModel::characteristic(double b_mm, double rpm, double f_hz) const {
  return characteristic_m(b_mm * 1e-3, rpm, f_hz);
}

bool LobeModel::stable(double b_mm, double rpm) const { return stable_m(b_mm * 1e-3, rpm); }

double LobeModel::critical_depth_mm(double rpm, double rel_tol) const {
  return critical_depth_m(rpm, rel_tol) * kMmPerM;
}

Complex LobeModel::characteristic_m(double b_m, double rpm, double f_hz) const {
  const double tau = 60.0 / (process_.teeth * rpm);
  const Complex regen = 1.0 - std::exp(Complex(0.0, -kTwoPi * f_hz * tau));
  const Complex lambda = -(process_.teeth / (4.0 * M_PI)) * process_.kt_n_per_m2 * b_m * regen;
  const Eigen::Matrix2cd m = Eigen::Matrix2cd::Identity() + lambda * oriented(f_hz);
  return m.determinant();
}

bool LobeModel::stable_m(double b_m, double rpm) const {
  // Nyquist on D(i w): the lobe grid (dense at resonances) merged with a uniform grid fine enough for the
  // delay term (8 points per period 1/tau of e^{-i w tau}), to 4x the lobe grid's top.
  const double tau = 60.0 / (process_.teeth * rpm);
  const double top = 4.0 * grid_hz_.back(), step = 1.0 / (8.0 * tau);
  std::vector<double> grid = grid_hz_;
  grid.push_back(0.0);
  for (double f = step; f < top; f += step) grid.push_back(f);
  for (double f = grid_hz_.back(); f < top; f *= 1.01) grid.push_back(f);
  grid.push_back(top);
  std::sort(grid.begin(), grid.end());
  const double t = analysis::turns([&](double f) { return characteristic_m(b_m, rpm, f); }, grid);
  return std::lround(2.0 * t) == 0;
}

double LobeModel::critical_depth_m(double rpm, double rel_tol) const {
  double lo = 0.0, hi = 1e-5;
  while (stable_m(hi, rpm)) {
    lo = hi;
    hi *= 2.0;
    if (hi > 100.0) return kInf;
  }
  while (hi - lo > rel_tol * hi) {
    const double mid = 0.5 * (lo + hi);
    (stable_m(mid, rpm) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace robodamp::milling
