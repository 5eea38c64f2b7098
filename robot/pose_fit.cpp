#include "robot/pose_fit.hpp"

#include <cmath>

#include <nlopt.h>

#include <functional>
#include <optional>

#include "config/number_range.hpp"
#include "robot/robot_model.hpp"

namespace robodamp::robot {

namespace {

std::complex<double> pick(const Eigen::Matrix2cd& g, FrfDirection d) {
  return d == FrfDirection::kXX ? g(0, 0) : d == FrfDirection::kYY ? g(1, 1) : g(0, 1);
}

// The model at one pose in the form the fit compares (PoseFitSettings::modes).
class ModelAtPose {
 public:
  ModelAtPose(const config::RobotModelConfig& m, const std::vector<double>& q, int modes)
      : chain_(at_pose(m, q)),
        modes_(modes > 0 ? chain_.modes(static_cast<std::size_t>(modes)) : std::vector<Mode>{}),
        modal_(modes > 0) {}
  [[nodiscard]] std::complex<double> at(double f_hz, FrfDirection d) const {
    return pick(modal_ ? modal_tcp_frf(modes_, f_hz) : chain_.tcp_frf_direct(f_hz), d);
  }

 private:
  PlanarChain chain_;
  std::vector<Mode> modes_;
  bool modal_;
};

struct Band {
  std::vector<double> f;
  std::vector<std::complex<double>> h;
  std::vector<double> w;
};

config::RobotModelConfig with_joints(config::RobotModelConfig m, const std::vector<double>& x,
                                     const PoseFitSettings& s) {
  const std::size_t n = m.joints.size();
  for (std::size_t j = 0; j < n; ++j) {
    m.joints[j].stiffness_nm_per_rad = std::pow(10.0, x[j]);
    if (s.fit_damping) m.joints[j].damping_ratio = x[n + j];
  }
  return m;
}

// Each pose's weighted relative error, squared; plus log_weight times its weighted mean squared error of
// the log magnitude (the swarm's smoother landscape).
std::vector<double> pose_errors(const config::RobotModelConfig& m, const std::vector<MeasuredFrf>& data,
                                const std::vector<Band>& bands, const PoseFitSettings& s, double log_weight = 0.0) {
  std::vector<double> out;
  for (std::size_t p = 0; p < data.size(); ++p) {
    const ModelAtPose c(m, data[p].joints_deg, s.modes);
    double num = 0.0, den = 0.0, num_log = 0.0, den_log = 0.0;
    const Band& b = bands[p];
    for (std::size_t i = 0; i < b.f.size(); ++i) {
      const std::complex<double> h = c.at(b.f[i], s.direction);
      num += b.w[i] * std::norm(h - b.h[i]);
      den += b.w[i] * std::norm(b.h[i]);
      const double l = std::log(std::abs(h) / std::abs(b.h[i]));
      num_log += b.w[i] * l * l;
      den_log += b.w[i];
    }
    out.push_back(num / den + log_weight * num_log / den_log);
  }
  return out;
}

struct Objective {
  const std::function<double(const std::vector<double>&)>* cost;
  int evaluations{0};
};

double nlopt_cost(unsigned n, const double* x, double* /*grad*/, void* data) {
  auto* o = static_cast<Objective*>(data);
  ++o->evaluations;
  const double f = (*o->cost)(std::vector<double>(x, x + n));
  return std::isfinite(f) ? f : 1e300;
}

// BOBYQA from x within [lo, hi]; x keeps the best point found (the swarm's if BOBYQA fails).
double polish(const std::function<double(const std::vector<double>&)>& cost, std::vector<double>& x,
              const std::vector<double>& lo, const std::vector<double>& hi, int max_evaluations, int& evaluations) {
  const auto n = static_cast<unsigned>(x.size());
  nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, n);
  Objective o{&cost};
  nlopt_set_lower_bounds(opt, lo.data());
  nlopt_set_upper_bounds(opt, hi.data());
  nlopt_set_min_objective(opt, nlopt_cost, &o);
  nlopt_set_xtol_rel(opt, 1e-6);
  nlopt_set_maxeval(opt, max_evaluations);
  std::vector<double> y = x;
  double f = 0.0;
  const nlopt_result rc = nlopt_optimize(opt, y.data(), &f);
  nlopt_destroy(opt);
  evaluations += o.evaluations;
  const double before = cost(x);
  if (rc > 0 && f < before) {
    x = y;
    return f;
  }
  return before;
}

// Each pose's points in the fit band (thinned), weighted by their magnitude.
std::vector<Band> fit_bands(const config::RobotModelConfig& model, const std::vector<MeasuredFrf>& data,
                            const PoseFitSettings& s, int max_points) {
  std::vector<Band> bands;
  for (const auto& d : data) {
    if (auto p = config::pose_problem(model, d.joints_deg))
      throw config::ConfigError({config::Problem{d.name, {}, "pose", *p}});
    Band b;
    double peak = 0.0;
    for (std::size_t i = 0; i < d.freq_hz.size(); ++i)
      if (d.freq_hz[i] >= s.band_min_hz && d.freq_hz[i] <= s.band_max_hz &&
          std::isfinite(std::abs(d.receptance_m_per_n[i])))
        b.f.push_back(d.freq_hz[i]), b.h.push_back(d.receptance_m_per_n[i]),
            peak = std::max(peak, std::abs(d.receptance_m_per_n[i]));
    if (static_cast<int>(b.f.size()) > max_points) {  // thinned evenly: each point costs a solve
      Band t;
      const double step = static_cast<double>(b.f.size() - 1) / (max_points - 1);
      for (int i = 0; i < max_points; ++i) {
        const auto k = static_cast<std::size_t>(std::lround(i * step));
        t.f.push_back(b.f[k]), t.h.push_back(b.h[k]);
      }
      b = std::move(t);
    }
    if (b.f.size() < 8 || !(peak > 0.0))
      throw config::ConfigError(
          {config::Problem{d.name,
                           {},
                           "",
                           "fewer than 8 usable points in the fit band " + config::format_number(s.band_min_hz) + "-" +
                               config::format_number(s.band_max_hz) + " Hz"}});
    for (const auto& h : b.h) b.w.push_back(std::abs(h) / peak);
    bands.push_back(std::move(b));
  }
  return bands;
}

}  // namespace

std::vector<double> model_errors(const config::RobotModelConfig& model, const std::vector<MeasuredFrf>& data,
                                 const PoseFitSettings& s) {
  std::vector<double> out;
  for (double e : pose_errors(model, data, fit_bands(model, data, s, s.final_points_per_pose), s))
    out.push_back(std::sqrt(e));
  return out;
}

MeasuredFrf model_frf(const config::RobotModelConfig& model, const MeasuredFrf& at, FrfDirection direction,
                      double f_lo_hz, double f_hi_hz, int modes) {
  if (auto p = config::pose_problem(model, at.joints_deg))
    throw config::ConfigError({config::Problem{at.name, {}, "pose", *p}});
  const ModelAtPose c(model, at.joints_deg, modes);
  MeasuredFrf out{at.name, at.joints_deg, {}, {}};
  for (const double f : at.freq_hz)
    if (f >= f_lo_hz && f <= f_hi_hz) out.freq_hz.push_back(f), out.receptance_m_per_n.push_back(c.at(f, direction));
  return out;
}

std::vector<double> peak_hz(const config::RobotModelConfig* model, const std::vector<MeasuredFrf>& data,
                            const PoseFitSettings& s) {
  std::vector<double> out;
  for (const MeasuredFrf& d : data) {
    double best = -1.0, at = 0.0;
    const std::optional<ModelAtPose> c =
        model ? std::optional<ModelAtPose>(ModelAtPose(*model, d.joints_deg, s.modes)) : std::nullopt;
    for (std::size_t i = 0; i < d.freq_hz.size(); ++i) {
      const double f = d.freq_hz[i];
      if (f < s.band_min_hz || f > s.band_max_hz) continue;
      const double m = c ? std::abs(c->at(f, s.direction)) : std::abs(d.receptance_m_per_n[i]);
      if (m > best) best = m, at = f;
    }
    out.push_back(at);
  }
  return out;
}

PoseFitResult fit_joints(const config::RobotModelConfig& model, const std::vector<MeasuredFrf>& data,
                         const PoseFitSettings& s) {
  if (data.empty()) throw config::ConfigError({config::Problem{model.source, {}, "", "no measured FRF to fit"}});
  // The modal form costs one eigen-solve per pose whatever the points: it searches on the model as written
  // over the final points. The direct form costs a solve per point: it searches coarse and thinned.
  const bool modal = s.modes > 0;
  const std::vector<Band> bands = fit_bands(model, data, s, modal ? s.final_points_per_pose : s.max_points_per_pose);
  const std::size_t n = model.joints.size();
  std::vector<double> lo(n, std::log10(s.stiffness_min_nm_per_rad)), hi(n, std::log10(s.stiffness_max_nm_per_rad));
  if (s.fit_damping) lo.insert(lo.end(), n, s.damping_min), hi.insert(hi.end(), n, s.damping_max);
  config::RobotModelConfig coarse = model;
  if (!modal && s.search_elements > 0)
    for (auto& l : coarse.links) l.elements = std::min(l.elements, s.search_elements);
  const auto mean_error = [&](const std::vector<double>& x, double log_weight) {
    double sum = 0.0;
    for (double e : pose_errors(with_joints(coarse, x, s), data, bands, s, log_weight)) sum += e;
    return sum / static_cast<double>(data.size());
  };
  const std::function<double(const std::vector<double>&)> cost = [&](const std::vector<double>& x) {
    return mean_error(x, 0.0);
  };
  // The swarm also weighs the log-magnitude error, smooth where the complex error is rugged (a mode a little
  // off in frequency turns its phase over): on the two measured planar robots of docs/pose_dynamics.md 8 and
  // 4 of 8 restarts reach the best basin, against 2 and 1 of 8 on the complex error alone. BOBYQA then
  // polishes the complex error alone.
  const std::function<double(const std::vector<double>&)> swarm_cost = [&](const std::vector<double>& x) {
    return mean_error(x, 1.0);
  };
  PoseFitResult r;
  std::vector<std::vector<double>> ks;
  PsoResult best;
  best.best_cost = INFINITY;
  for (int k = 0; k < std::max(1, s.restarts); ++k) {
    PsoSettings ps = s.pso;
    ps.seed = s.pso.seed + static_cast<std::uint64_t>(k);
    PsoResult one = particle_swarm(swarm_cost, lo, hi, ps);
    r.evaluations += one.evaluations;
    if (s.polish) one.best_cost = polish(cost, one.best, lo, hi, s.polish_evaluations, r.evaluations);
    r.restart_costs.push_back(one.best_cost);
    std::vector<double> kk;
    for (std::size_t j = 0; j < n; ++j) kk.push_back(std::pow(10.0, one.best[j]));
    ks.push_back(kk);
    if (one.best_cost < best.best_cost) best = std::move(one);
  }
  r.fitted = with_joints(model, best.best, s);
  // The spread over the restarts that found the best basin (weighted relative error within 0.5 percentage
  // points of the best); the others are counted, not averaged in.
  std::vector<const std::vector<double>*> converged;
  for (std::size_t k = 0; k < ks.size(); ++k)
    if (std::sqrt(r.restart_costs[k]) <= std::sqrt(best.best_cost) + 0.005) converged.push_back(&ks[k]);
  r.converged_restarts = static_cast<int>(converged.size());
  for (std::size_t j = 0; j < n; ++j) {
    r.stiffness_nm_per_rad.push_back(r.fitted.joints[j].stiffness_nm_per_rad);
    r.damping_ratio.push_back(r.fitted.joints[j].damping_ratio);
    double mean = 0.0, var = 0.0;
    for (const auto* kk : converged) mean += (*kk)[j];
    mean /= static_cast<double>(converged.size());
    for (const auto* kk : converged) var += ((*kk)[j] - mean) * ((*kk)[j] - mean);
    r.stiffness_spread_pct.push_back(100.0 * std::sqrt(var / static_cast<double>(converged.size())) / mean);
  }
  r.pose_error = model_errors(r.fitted, data, s);
  return r;
}

}  // namespace robodamp::robot
