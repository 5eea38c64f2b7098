#include "robot/modal_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "robot/robot_model.hpp"

namespace robodamp::robot {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kDegToRad = M_PI / 180.0;
// A measured mode stands for a model mode when their frequencies are within 25 %.
const double kMatchLogRatio = std::log(1.25);
// The identification's scatter assumed (one standard deviation; the regression's nugget): a fitted mode's
// frequency 0.3 %, its damping ratio 3 %, its participation 1 % of the track's largest. Larger values smooth
// more.
// The tracks' keys: a model mode's index, or this plus the rank among the modes no model mode matches.
constexpr int kUnmatchedKey = 1 << 20;
constexpr double kFreqNoise = 0.003, kDampingNoise = 0.03, kStiffnessNoise = 0.01;
// A mode's participation along the axis, w^2 / k (1/kg: the mass-normalised shape squared) is what is
// interpolated for its stiffness: it is smooth through a pose where the mode turns across the axis (there k
// goes to infinity and its logarithm with it). A mapped participation below this share of the model's is held
// there (the mode hardly moves the TCP along the axis); a relative spread is at most kMaxRelativeSigma.
constexpr double kParticipationFloor = 1e-3, kMaxRelativeSigma = 10.0;
double participation(double f_hz, double k_n_per_m) {
  const double w = kTwoPi * f_hz;
  return w * w / k_n_per_m;
}
// The length scales tried (rad over the joints): from one joint's few degrees to the whole travel.
constexpr double kLengthScalesRad[] = {0.05, 0.08, 0.12, 0.18, 0.25, 0.35, 0.5, 0.7, 1.0, 1.5, 2.5};

Eigen::VectorXd radians(const std::vector<double>& q_deg) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(q_deg.size()));
  for (std::size_t i = 0; i < q_deg.size(); ++i) x(static_cast<Eigen::Index>(i)) = q_deg[i] * kDegToRad;
  return x;
}

Eigen::MatrixXd correlation(const std::vector<Eigen::VectorXd>& x, double length_rad, double nugget) {
  const auto n = static_cast<Eigen::Index>(x.size());
  Eigen::MatrixXd r(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      r(i, j) = std::exp(-0.5 * (x[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(j)]).squaredNorm() /
                         (length_rad * length_rad)) +
                (i == j ? nugget : 0.0);
  return r;
}

// One quantity's regression in the form that predicts the measured poses best: against the model's mode
// (prior: the quantity minus the model's, in the same units) or the track's own values, scored by leaving each
// measured pose out in turn (the regression fitted anew on the others, its length scale too) and summing the
// squared errors there. The model is the prior by default: its own form must predict better, and it is tried
// from three poses on (with two, leaving one out says nothing about the shape between). On the robot wrong in
// form (docs/pose_dynamics.md) the model's damping varies with the pose where the measured damping is flat, and
// its participation passes through zero where the measured one peaks: there the track's own form wins.
double leave_one_out_sse(const std::vector<Eigen::VectorXd>& x, const std::vector<double>& y, double noise,
                         bool about_mean) {
  double sse = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::vector<Eigen::VectorXd> xs;
    std::vector<double> ys;
    for (std::size_t j = 0; j < x.size(); ++j)
      if (j != i) xs.push_back(x[j]), ys.push_back(y[j]);
    const double e = ModalMap::Field(std::move(xs), std::move(ys), noise, about_mean).mean(x[i]) - y[i];
    sse += e * e;
  }
  return sse;
}

ModalMap::Field fitted_form(const std::vector<Eigen::VectorXd>& x, const std::vector<double>& own,
                            const std::vector<double>& against_model, double noise, QuantityForm& form) {
  const double n = static_cast<double>(x.size());
  form.own_rms = x.size() >= 2 ? std::sqrt(leave_one_out_sse(x, own, noise, true) / n) : 0.0;
  form.model_rms =
      !against_model.empty() && x.size() >= 2 ? std::sqrt(leave_one_out_sse(x, against_model, noise, false) / n) : 0.0;
  form.own = against_model.empty() || (x.size() >= 3 && form.own_rms < form.model_rms);
  return form.own ? ModalMap::Field(x, own, noise, true) : ModalMap::Field(x, against_model, noise, false);
}

// A measured mode at one pose, with the model's mode it was matched to there (model_index -1: none). absent:
// at a measured pose the track's model mode lies where the measurement would have seen it (below the highest
// mode measured there, within the match's 25 %) and no measured mode was matched to it: it hardly moves the
// TCP along the axis there, a participation of zero; its frequency and damping are not known there.
struct Sample {
  Eigen::VectorXd x;
  double f_hz, zeta, k, model_f_hz, model_zeta, model_k;
  int model_index;
  bool absent{false};
};
std::size_t present(const std::vector<Sample>& t) {
  return static_cast<std::size_t>(std::count_if(t.begin(), t.end(), [](const Sample& s) { return !s.absent; }));
}

// One measured mode over the poses (a track): each quantity in the form leave-one-out chooses, its model mode
// (-1 where no one model mode follows it at every pose), its frequencies.
void fit_track(const std::vector<Sample>& t, ModalMap::Field& freq, ModalMap::Field& damping,
               ModalMap::Field& stiffness, TrackForm& form) {
  form.model_index = t.front().model_index;
  for (const Sample& s : t)
    if (s.model_index != form.model_index) form.model_index = -1;
  const bool matched = form.model_index >= 0;
  std::vector<Eigen::VectorXd> x, x_all;  // the poses it was measured at; with those it is absent at
  // Each quantity in both forms: against the model's mode (a log ratio, or the participation's difference)
  // and as the track's own values.
  std::vector<double> f_own, f_prior, z_own, z_prior, p_own, p_model;
  double p_scale = 0.0;
  for (const Sample& s : t) {
    x_all.push_back(s.x);
    p_own.push_back(s.absent ? 0.0 : participation(s.f_hz, s.k));
    if (matched) p_model.push_back(participation(s.model_f_hz, s.model_k));
    if (s.absent) continue;
    x.push_back(s.x);
    f_own.push_back(std::log(s.f_hz));
    z_own.push_back(std::log(s.zeta));
    if (matched) {
      f_prior.push_back(std::log(s.model_f_hz));
      z_prior.push_back(std::log(s.model_zeta));
    }
    p_scale = std::max(p_scale, participation(s.f_hz, s.k));
  }
  const auto difference = [matched](const std::vector<double>& a, const std::vector<double>& b) {
    std::vector<double> d;
    for (std::size_t i = 0; matched && i < a.size(); ++i) d.push_back(a[i] - b[i]);
    return d;
  };
  freq = fitted_form(x, f_own, difference(f_own, f_prior), kFreqNoise, form.freq);
  damping = fitted_form(x, z_own, difference(z_own, z_prior), kDampingNoise, form.damping);
  stiffness = fitted_form(x_all, p_own, difference(p_own, p_model), kStiffnessNoise * p_scale, form.stiffness);
  form.measured_poses = static_cast<int>(x.size());
  form.min_hz = INFINITY;
  for (const Sample& s : t)
    if (!s.absent) form.min_hz = std::min(form.min_hz, s.f_hz), form.max_hz = std::max(form.max_hz, s.f_hz);
}

// The measured modes' indices among the model's: as many pairs within 25 % as possible, then the smallest
// sum of |log frequency ratio|. Small counts (a few modes each): searched exhaustively.
void best_assignment(const std::vector<double>& measured_hz, const std::vector<double>& model_hz, std::size_t i,
                     std::vector<int>& now, std::vector<bool>& used, int pairs, double cost, int& best_pairs,
                     double& best_cost, std::vector<int>& best) {
  if (i == measured_hz.size()) {
    if (pairs > best_pairs || (pairs == best_pairs && cost < best_cost))
      best_pairs = pairs, best_cost = cost, best = now;
    return;
  }
  now[i] = -1;
  best_assignment(measured_hz, model_hz, i + 1, now, used, pairs, cost, best_pairs, best_cost, best);
  for (std::size_t m = 0; m < model_hz.size(); ++m) {
    const double d = std::abs(std::log(measured_hz[i] / model_hz[m]));
    if (used[m] || !(d < kMatchLogRatio)) continue;
    used[m] = true, now[i] = static_cast<int>(m);
    best_assignment(measured_hz, model_hz, i + 1, now, used, pairs + 1, cost + d, best_pairs, best_cost, best);
    used[m] = false;
  }
  now[i] = -1;
}

std::vector<int> match_modes(const std::vector<double>& measured_hz, const std::vector<double>& model_hz) {
  std::vector<int> now(measured_hz.size(), -1), best(measured_hz.size(), -1);
  std::vector<bool> used(model_hz.size(), false);
  int best_pairs = -1;
  double best_cost = std::numeric_limits<double>::infinity();
  best_assignment(measured_hz, model_hz, 0, now, used, 0, 0.0, best_pairs, best_cost, best);
  return best;
}

}  // namespace

std::vector<AxisMode> axis_modes(const config::RobotModelConfig& model, const std::vector<double>& q, int axis,
                                 int count) {
  const PlanarChain chain = at_pose(model, q);
  std::vector<AxisMode> out;
  for (const Mode& md : chain.modes(static_cast<std::size_t>(count))) {
    const double phi = md.tcp_shape(axis);
    const double w = kTwoPi * md.freq_hz;
    if (!(std::abs(phi) > 0.0) || !(w > 0.0)) continue;  // a mode that does not move the TCP along the axis
    out.push_back({md.freq_hz, modal_damping_ratio(md), w * w / (phi * phi), md.tcp_shape});
  }
  return out;
}

ModalMap::Field::Field(std::vector<Eigen::VectorXd> x, std::vector<double> y, double noise, bool about_mean)
    : x_(std::move(x)) {
  const auto n = static_cast<Eigen::Index>(y.size());
  if (n == 0) return;
  const Eigen::VectorXd yv = Eigen::Map<const Eigen::VectorXd>(y.data(), n);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  const double noise_var = noise * noise;
  // Far from every measurement the model is no better than its whole error there: the signal's variance
  // is at least the mean square of the ratios (and at least the noise's).
  const double centre = about_mean ? yv.mean() : 0.0;
  const double floor_var = std::max((yv.array() - centre).square().sum() / static_cast<double>(n), noise_var);
  // Scales longer than the measured poses' span are not tried: the poses are then one value to the kernel and its
  // mean is ill-posed (the sine's far-away mean -0.27 at 2.5 rad from data spanning 1.2 rad).
  double span_rad = 0.0;
  for (const auto& a : x_)
    for (const auto& b : x_) span_rad = std::max(span_rad, (a - b).norm());
  std::vector<double> log_likelihood;
  for (const double l : kLengthScalesRad) {
    if (l > span_rad && l > kLengthScalesRad[0]) break;
    Scale c;
    c.length_rad = l;
    double var = floor_var, ll = 0.0;
    for (int it = 0; it < 4; ++it) {  // the signal's variance profiled; the nugget follows it
      const Eigen::LDLT<Eigen::MatrixXd> r(correlation(x_, l, noise_var / var));
      const Eigen::VectorXd ri1 = r.solve(ones);
      const double mu = ones.dot(r.solve(yv)) / ones.dot(ri1);
      const Eigen::VectorXd e = yv - mu * ones;
      const double s2 = n > 1 ? e.dot(r.solve(e)) / static_cast<double>(n - 1) : floor_var;
      var = std::max(s2, noise_var);
      const Eigen::VectorXd d = r.vectorD();
      double log_det = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) log_det += std::log(std::max(d(i), 1e-300));
      ll = -0.5 * (static_cast<double>(n - 1) * std::log(var) + log_det + std::log(ones.dot(ri1)));
    }
    c.signal_var = std::max(var, floor_var);
    c.r.compute(correlation(x_, l, noise_var / c.signal_var));
    c.r_ones = c.r.solve(ones);
    c.ones_r_ones = ones.dot(c.r_ones);
    c.mu = ones.dot(c.r.solve(yv)) / c.ones_r_ones;
    c.alpha = c.r.solve(yv - c.mu * ones);
    scales_.push_back(std::move(c));
    log_likelihood.push_back(ll);
  }
  // Each length scale weighted by its likelihood (a uniform prior over the log-spaced grid): with few poses the
  // likelihood hardly prefers one, and choosing the best made the map jump between two scales when a
  // measurement moved by its noise (a held-out stop's mode 0.6 % off in one run, 2.3 % in the next).
  const double best = *std::max_element(log_likelihood.begin(), log_likelihood.end());
  double sum = 0.0;
  for (std::size_t i = 0; i < scales_.size(); ++i) sum += scales_[i].weight = std::exp(log_likelihood[i] - best);
  for (Scale& c : scales_) c.weight /= sum;
}

Eigen::VectorXd ModalMap::Field::kernel_column(const Eigen::VectorXd& x, double length_rad) const {
  Eigen::VectorXd c(static_cast<Eigen::Index>(x_.size()));
  for (std::size_t i = 0; i < x_.size(); ++i)
    c(static_cast<Eigen::Index>(i)) = std::exp(-0.5 * (x - x_[i]).squaredNorm() / (length_rad * length_rad));
  return c;
}

double ModalMap::Field::mean(const Eigen::VectorXd& x) const {
  double m = 0.0;
  for (const Scale& c : scales_) m += c.weight * (c.mu + kernel_column(x, c.length_rad).dot(c.alpha));
  return m;
}

// The mixture's mean and spread (each scale's variance and the scatter of their means) from one kernel column per
// scale.
ModalMap::Field::Estimate ModalMap::Field::estimate(const Eigen::VectorXd& x) const {
  double m = 0.0, second = 0.0;
  for (const Scale& c : scales_) {
    const Eigen::VectorXd k = kernel_column(x, c.length_rad);
    const double trend = 1.0 - c.r_ones.dot(k);
    const double v = std::max(0.0, c.signal_var * (1.0 - k.dot(c.r.solve(k)) + trend * trend / c.ones_r_ones));
    const double mi = c.mu + k.dot(c.alpha);
    m += c.weight * mi;
    second += c.weight * (v + mi * mi);
  }
  return {m, std::sqrt(std::max(0.0, second - m * m))};
}

ModalMap::ModalMap(const config::RobotModelConfig& model, int axis, int count) : count_(count) {
  if (!model.measured_modes || model.measured_modes->poses.empty())
    throw std::invalid_argument(model.source + ": no measured_modes to interpolate");
  if (model.measured_modes->axis != axis)
    throw std::invalid_argument(model.source + ": measured_modes are along " +
                                (model.measured_modes->axis == 0 ? "x" : "y") + ", the schedule's axis is " +
                                (axis == 0 ? "x" : "y") + ": measure along the actuator's axis");
  // The tracks: a measured mode matched to a model mode joins that mode's track (the model's order is the prior's
  // identity of a mode: a mode a driving point misses at some poses does not shift the others); the modes the
  // model has no match for, by their rank among the unmatched at each pose.
  std::map<int, std::vector<Sample>> by_key;
  struct Seen {  // at one measured pose: the model's modes there, which of them a measured mode matched, the highest
    Eigen::VectorXd x;
    std::vector<AxisMode> prior;
    std::vector<bool> matched;
    double highest_hz{0.0};
  };
  std::vector<Seen> seen;
  for (const config::MeasuredPoseModes& p : model.measured_modes->poses) {
    const std::vector<AxisMode> prior = axis_modes(model, p.joints_deg, axis, count);
    std::vector<config::ModeConfig> measured = p.modes;
    std::sort(measured.begin(), measured.end(),
              [](const auto& l, const auto& r) { return l.natural_freq_hz < r.natural_freq_hz; });
    std::vector<double> measured_hz, model_hz;
    for (const auto& m : measured) measured_hz.push_back(m.natural_freq_hz);
    for (const auto& m : prior) model_hz.push_back(m.freq_hz);
    PoseMatch match{p.name, match_modes(measured_hz, model_hz)};
    Seen here{radians(p.joints_deg), prior, std::vector<bool>(prior.size(), false), 0.0};
    int unmatched = 0;
    for (std::size_t k = 0; k < measured.size(); ++k) {
      const int j = match.model_of_measured[k];
      const AxisMode a = j >= 0 ? prior[static_cast<std::size_t>(j)] : AxisMode{};
      by_key[j >= 0 ? j : kUnmatchedKey + unmatched++].push_back(
          {here.x, measured[k].natural_freq_hz, measured[k].damping_ratio, measured[k].stiffness_n_per_m, a.freq_hz,
           a.damping_ratio, a.stiffness_n_per_m, j});
      if (j >= 0) here.matched[static_cast<std::size_t>(j)] = true;
      here.highest_hz = std::max(here.highest_hz, measured[k].natural_freq_hz);
    }
    seen.push_back(std::move(here));
    matches_.push_back(std::move(match));
    measured_deg_.push_back(p.joints_deg);
  }
  // Where a tracked model mode was not seen at a measured pose that would have seen it, it is there but does
  // not move the TCP along the axis: without this the regression carried its participation from the poses
  // where it does into one where the measurement showed nothing (a mode along y at 21 Hz given 5.9e5 N/m along
  // x, where the robot's is 7e9).
  for (auto& [key, t] : by_key) {
    if (key < 0 || key >= kUnmatchedKey) continue;
    const auto j = static_cast<std::size_t>(key);
    for (const Seen& p : seen)
      if (j < p.prior.size() && !p.matched[j] && p.prior[j].freq_hz <= p.highest_hz * std::exp(kMatchLogRatio))
        t.push_back({p.x, NAN, NAN, INFINITY, p.prior[j].freq_hz, p.prior[j].damping_ratio,
                     p.prior[j].stiffness_n_per_m, key, true});
  }
  std::vector<std::vector<Sample>> tracks;
  for (auto& [key, t] : by_key) tracks.push_back(std::move(t));
  const auto mean_hz = [](const std::vector<Sample>& t) {
    double sum = 0.0;
    for (const Sample& x : t)
      if (!x.absent) sum += x.f_hz;
    return sum / static_cast<double>(std::max<std::size_t>(present(t), 1));
  };
  std::sort(tracks.begin(), tracks.end(), [&](const auto& a, const auto& b) { return mean_hz(a) < mean_hz(b); });
  for (const std::vector<Sample>& t : tracks) {
    if (2 * present(t) < model.measured_modes->poses.size()) continue;  // seen at too few poses to stand for a mode
    Track tr;
    fit_track(t, tr.freq, tr.damping, tr.stiffness, tr.form);
    tr.model_index = tr.form.model_index;
    tracks_.push_back(std::move(tr));
  }
}

std::vector<ModeCorrection> ModalMap::at(const std::vector<double>& q_deg, const std::vector<AxisMode>& prior) const {
  const Eigen::VectorXd x = radians(q_deg);
  std::vector<ModeCorrection> out;
  std::vector<bool> followed(prior.size(), false);
  for (const Track& t : tracks_) {
    const bool own = t.model_index < 0 || static_cast<std::size_t>(t.model_index) >= prior.size();
    const AxisMode a = own ? AxisMode{} : prior[static_cast<std::size_t>(t.model_index)];
    ModeCorrection c;
    c.measured_poses = static_cast<int>(t.freq.points());
    c.model_index = own ? -1 : t.model_index;
    if (!own) followed[static_cast<std::size_t>(t.model_index)] = true;
    // A quantity in its own form is the track's value; against the model, the model's times the ratio (or plus
    // the participation's difference).
    const double f_model = own ? 1.0 : a.freq_hz, z_model = own ? 1.0 : a.damping_ratio;
    const Field::Estimate f = t.freq.estimate(x), z = t.damping.estimate(x), pe = t.stiffness.estimate(x);
    c.freq_hz = (own || t.form.freq.own ? 1.0 : f_model) * std::exp(f.mean);
    c.damping_ratio = (own || t.form.damping.own ? 1.0 : z_model) * std::exp(z.mean);
    c.freq_scale = own ? 1.0 : c.freq_hz / f_model;
    c.damping_scale = own ? 1.0 : c.damping_ratio / z_model;
    c.freq_sigma = f.sigma;
    c.damping_sigma = z.sigma;
    // The participation w^2 / k: the model's plus the regression's (or its own); the stiffness from it at the
    // mapped frequency.
    const double p_model = own ? 0.0 : participation(a.freq_hz, a.stiffness_n_per_m);
    const double p = (t.form.stiffness.own ? 0.0 : p_model) + pe.mean;
    const double p_floor = kParticipationFloor * std::max(p_model, std::abs(p)) + std::numeric_limits<double>::min();
    const double w = kTwoPi * c.freq_hz;
    c.stiffness_n_per_m = w * w / std::max(p, p_floor);
    c.stiffness_scale = own ? 1.0 : c.stiffness_n_per_m / a.stiffness_n_per_m;
    c.stiffness_sigma = std::min(kMaxRelativeSigma, pe.sigma / std::max(p, p_floor));
    out.push_back(c);
  }
  // The model's modes no track follows, above every track: below the highest, the measurements would have
  // seen them.
  double highest_track_hz = 0.0;
  for (const ModeCorrection& c : out) highest_track_hz = std::max(highest_track_hz, c.freq_hz);
  for (std::size_t i = 0; i < prior.size(); ++i) {
    if (followed[i] || prior[i].freq_hz <= highest_track_hz) continue;
    ModeCorrection c;
    c.freq_hz = prior[i].freq_hz;
    c.damping_ratio = prior[i].damping_ratio;
    c.stiffness_n_per_m = prior[i].stiffness_n_per_m;
    c.model_index = static_cast<int>(i);
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const auto& l, const auto& r) { return l.freq_hz < r.freq_hz; });
  if (out.size() > static_cast<std::size_t>(count_))
    out.resize(static_cast<std::size_t>(count_));  // the plant's N lowest
  return out;
}

std::vector<TrackForm> ModalMap::forms() const {
  std::vector<TrackForm> out;
  for (const Track& t : tracks_) out.push_back(t.form);
  return out;
}

double ModalMap::nearest_measured_deg(const std::vector<double>& q_deg) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& m : measured_deg_) {
    double s = 0.0;
    for (std::size_t i = 0; i < m.size() && i < q_deg.size(); ++i) s += (m[i] - q_deg[i]) * (m[i] - q_deg[i]);
    best = std::min(best, std::sqrt(s));
  }
  return best;
}

}  // namespace robodamp::robot
