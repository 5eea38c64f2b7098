// `robodamp monitor`: a live text view of a running loop from its DDS topics (runtime/monitor_view.hpp).
#include <unistd.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <thread>

#include "apps/cli.hpp"
#include "apps/dds_client.hpp"
#include "dds/latest_sample.hpp"
#include "dds/participant.hpp"
#include "rt/signals.hpp"
#include "rt/supervisor.hpp"
#include "runtime/monitor_view.hpp"

namespace robodamp::apps {

using Clock = std::chrono::steady_clock;
using dds::Latest;

// Nothing new for this long: the monitor says the loop is out of contact (the dashboard's stale_after_s is 2 s;
// the status alone comes at dds.status_rate_hz, 5 Hz by default).
constexpr double kNoContactS = 3.0;

// 0 when it saw the loop (telemetry or status), 1 when nothing came.
int run_monitor(const DdsClientOptions& o) {
  rt::install_shutdown_handlers();
  auto cell = std::make_shared<std::string>(o.cell);  // empty: the first cell heard
  Latest<msg::Telemetry> telemetry(cell);             // before the participant: it outlives the readers that call it
  Latest<msg::Status> status(cell);
  Latest<msg::Machining> machining(cell);
  Latest<msg::Advice> advice(cell);
  dds::Participant p(o.domain_id, o.transport, "robodamp monitor", o.security);
  p.reader(dds::TopicKind::kTelemetry, &telemetry);
  p.reader(dds::TopicKind::kStatus, &status);
  p.reader(dds::TopicKind::kMachining, &machining);
  p.reader(dds::TopicKind::kAdvice, &advice);
  const bool tty = isatty(STDOUT_FILENO) != 0;
  std::cerr << "robodamp monitor: domain " << o.domain_id << " (" << config::to_string(o.transport)
            << "), waiting for a loop; Ctrl-C ends\n";
  const auto end = Clock::now() + std::chrono::duration<double>(o.duration_s);
  std::uint64_t shown = 0;
  auto heard = Clock::now();
  bool silent = false;  // said "no contact" and heard nothing since
  while (rt::shutdown_signal().load() == 0 && (o.duration_s <= 0.0 || Clock::now() < end)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const auto [t, nt] = telemetry.get();
    const auto [s, ns] = status.get();
    const auto [m, nm] = machining.get();
    const auto [a, na] = advice.get();
    if (nt + ns + nm + na == shown) {
      // A loop that stops publishing (ended, crashed, the link down) is said, not shown frozen.
      const double quiet_s = std::chrono::duration<double>(Clock::now() - heard).count();
      if (shown > 0 && !silent && quiet_s >= kNoContactS) {
        silent = true;
        std::cout << "robodamp monitor: NO CONTACT: nothing from " << (ns ? s.cell().c_str() : t.cell().c_str())
                  << " for " << static_cast<int>(quiet_s)
                  << " s: the loop stopped or the link is down (last seen: state "
                  << (nt ? rt::to_string(static_cast<rt::State>(t.state())) : s.state().c_str()) << " at loop time "
                  << (nt ? t.time_s() : s.time_s()) << " s); the view above is old\n"
                  << std::flush;
      }
      continue;
    }
    if (silent) std::cout << "robodamp monitor: contact again\n";
    silent = false;
    heard = Clock::now();
    shown = nt + ns + nm + na;
    if (tty) std::cout << "\x1b[H\x1b[2J";  // redraw in place
    std::cout << runtime::monitor_status_text(t, nt, s, ns) << (nm ? runtime::monitor_machining_text(m) : "")
              << (na ? runtime::monitor_advice_text(a) : "") << (tty ? "" : "\n") << std::flush;
  }
  return shown > 0 ? 0 : 1;
}

void register_monitor(Registry& r) {
  auto o = std::make_shared<DdsClientArgs>();
  CLI::App* sub = r.add("monitor",
                        "Live text view of a running loop from its DDS topics (state, vibration, command, saturation, "
                        "timing; with spindle.job the speed, depth, open and damped limits, the chatter indicator and "
                        "the latest spindle-speed advice)",
                        [o] {
                          const auto opts = resolve(*o);
                          return opts ? run_monitor(*opts) : 2;
                        });
  add_dds_options(r, sub, *o);
  r.number(sub, "--duration", o->options.duration_s, {"s", 0.0, 86400.0, false, false, "0 = until Ctrl-C"},
           "Stop after S seconds");
}

}  // namespace robodamp::apps
