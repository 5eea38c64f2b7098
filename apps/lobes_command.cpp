// `robodamp lobes`: stability lobes (semi-discretization by default, the zero-order method as a preview) with the direct test at chosen speeds, open loop
// and with the damping loop closed (--damped).
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "apps/milling_report.hpp"

namespace robodamp::apps {

namespace {

// 0 done, 1 plot failed, 2 configuration or option error.
int run_lobes(const MillingOptions& o) {
  config::MillingConfig cfg = config::load_milling_config(o.job_path);
  milling::apply_pose(cfg, o.pose_deg);
  // The direct test is defined where the job computes its lobes.
  const config::Range speeds{
      "rpm", cfg.lobes.rpm_min, cfg.lobes.rpm_max, false, false, "the job's lobes.rpm_min .. lobes.rpm_max"};
  for (double rpm : o.rpm) {
    if (auto p = config::range_problem("--rpm", rpm, speeds)) {
      std::cerr << "robodamp lobes: " << *p << '\n';
      return 2;
    }
  }
  return print_lobes(lobes_report(cfg, o), o);
}

}  // namespace

void register_lobes(Registry& r) {
  auto o = std::make_shared<MillingOptions>();
  CLI::App* sub = r.add(
      "lobes", "Stability lobes (semi-discretization of what runs, or a zero-order preview), open loop and --damped",
      [o] { return run_lobes(*o); });
  add_milling_options(r, sub, *o, "lobes");
  sub->add_option("--method", o->method,
                  "sdm (default): semi-discretization of what runs, open loop and the sampled damped loop "
                  "(time_domain.sdm_*); zoa: the zero-order method, a fast preview")
      ->check(CLI::IsMember({"zoa", "sdm"}));
  r.numbers(sub, "--rpm", o->rpm, {"rpm", 0.0, 200000.0, true, false, "and within the job's lobes speed range"},
            "Limiting depth at these speeds by the direct test (the spindle speed is always included)");
  r.numbers(sub, "--pose", o->pose_deg, {"deg", -360.0, 360.0},
            "The robot's joint angles for the job's pose parts (config/robots/*.yaml)");
}

}  // namespace robodamp::apps
