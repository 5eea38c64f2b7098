// `robodamp sle`: surface location error over the speed range and at the job's test conditions, with
// path compensation, open loop and with the damping loop closed (--damped).
#include <memory>

#include "apps/cli.hpp"
#include "apps/milling_report.hpp"

namespace robodamp::apps {

void register_sle(Registry& r) {
  auto o = std::make_shared<MillingOptions>();
  CLI::App* sub = r.add("sle", "Surface location error over speed and at the test conditions, with compensation", [o] {
    config::MillingConfig cfg = config::load_milling_config(o->job_path);
    milling::apply_pose(cfg, o->pose_deg);
    return print_sle(sle_report(cfg, *o), *o);
  });
  add_milling_options(r, sub, *o, "sle");
  r.numbers(sub, "--pose", o->pose_deg, {"deg", -360.0, 360.0},
            "The robot's joint angles for the job's pose parts (config/robots/*.yaml)");
}

}  // namespace robodamp::apps
