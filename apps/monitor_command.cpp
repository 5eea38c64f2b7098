// `robodamp monitor`: a live text view of a running loop from its DDS topics (runtime/monitor_view.hpp).
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "apps/dds_client.hpp"
#include "runtime/monitor_view.hpp"

namespace robodamp::apps {

void register_monitor(Registry& r) {
  auto o = std::make_shared<DdsClientArgs>();
  CLI::App* sub = r.add("monitor",
                        "Live text view of a running loop from its DDS topics (state, vibration, command, saturation, "
                        "timing; with spindle.job the speed, depth, open and damped limits, the chatter indicator and "
                        "the latest spindle-speed advice)",
                        [o] {
                          const auto opts = dds::resolve(*o, std::cerr);
                          return opts ? runtime::watch_cell(*opts, std::cout, std::cerr) : 2;
                        });
  add_dds_options(r, sub, *o);
  r.number(sub, "--duration", o->options.duration_s, {"s", 0.0, 86400.0, false, false, "0 = until Ctrl-C"},
           "Stop after S seconds");
}

}  // namespace robodamp::apps
