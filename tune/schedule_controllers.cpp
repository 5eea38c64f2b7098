#include "tune/schedule_controllers.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "config/config.hpp"
#include "config/speed_schedule_config.hpp"
#include "control/controller.hpp"

namespace robodamp::tune {

namespace {

// The gains written are the ones verified: 3 significant figures, rounded down (the margins hold).
double three_figures(double x) {
  if (!(x > 0.0)) return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 2.0);
  return std::floor(x / scale) * scale;  // down: the margins hold
}

// The largest K whose loop keeps every margin (log scan, then bisection): what a candidate may go up to.
void set_top_gain(ScheduleController& c, const config::Config& cell, const ScheduleSettings& s) {
  c.k_max_ns_per_m = analysis::max_stable_gain(*c.model, c.polarity);
  const double ceiling = cell.supervision.max_gain_fraction * c.k_max_ns_per_m.value_or(control::kMaxGainNsPerM);
  std::string why;
  auto ok = [&](double k) {
    if (!c.model->stable(k, c.polarity)) return why = "the loop is unstable", false;
    const analysis::Margins m = analysis::margins(*c.model, k, c.polarity, c.k_max_ns_per_m);
    if (m.gain_margin_db && *m.gain_margin_db < s.gain_margin_min_db) return why = "gain margin", false;
    if (m.phase_margin_deg && *m.phase_margin_deg < s.phase_margin_min_deg) return why = "phase margin", false;
    if (m.delay_margin_ms && *m.delay_margin_ms < s.delay_margin_min_ms) return why = "delay margin", false;
    return true;
  };
  constexpr double kFloor = 1.0;
  if (!ok(kFloor)) {
    c.top_gain_reason = "no K keeps the margins (" + why + ")";
    return;
  }
  double lo = kFloor, hi = ceiling;
  std::string fail_reason = "supervision.max_gain_fraction of K_max";
  for (int i = 1; i <= 48; ++i) {  // the first failure on a log scan, then bisection below it
    const double k = kFloor * std::pow(ceiling / kFloor, i / 48.0);
    if (!ok(k)) {
      hi = k;
      fail_reason = why;
      break;
    }
    lo = k;
  }
  if (lo < hi && hi < ceiling) {
    while (hi / lo > 1.001) {
      const double mid = std::sqrt(lo * hi);
      (ok(mid) ? lo : hi) = mid;
    }
  }
  c.top_gain_ns_per_m = lo;
  c.top_gain_reason = fail_reason;
  for (int i = 0; i < s.gains_per_controller; ++i)
    c.gains.push_back(three_figures(lo / std::pow(16.0, static_cast<double>(s.gains_per_controller - 1 - i) /
                                                            std::max(1, s.gains_per_controller - 1))));
  c.gains.erase(std::unique(c.gains.begin(), c.gains.end()), c.gains.end());
}

}  // namespace

std::vector<ScheduleController> schedule_controllers(const config::Config& cell,
                                                     const std::vector<NamedController>& others,
                                                     const ScheduleSettings& s) {
  std::vector<ScheduleController> out;
  auto add = [&](const std::string& file, config::Config cfg) {
    cfg.controller.speed_schedule.reset();
    ScheduleController c;
    c.file = file;
    c.polarity = cfg.controller.polarity;
    c.model = std::make_shared<const analysis::LoopModel>(cfg);
    c.config = std::move(cfg);
    set_top_gain(c, cell, s);
    out.push_back(std::move(c));
  };
  add("", cell);
  for (const auto& o : others) {
    add(o.name, config::with_speed_controller(cell, o.controller));
    out.back().entry = o.controller;
  }
  return out;
}

NamedController controller_of_file(const std::string& path) {
  return {path, config::speed_controller_of(config::load_config_file(path))};
}

}  // namespace robodamp::tune
