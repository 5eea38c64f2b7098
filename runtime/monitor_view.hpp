// What `robodamp monitor` shows of a running cell from its DDS topics: the loop's state, vibration, command,
// timing and availability; with spindle.job the speed, depth, limits and chatter indicator; the latest
// spindle-speed advice. Off the real-time path.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "dds/client_options.hpp"
#include "dds/messages.hpp"

namespace robodamp::runtime {

// nt, ns: how many telemetry and status samples were heard (0: none yet, the fields shown as such).
[[nodiscard]] std::string monitor_status_text(const msg::Telemetry& t, std::uint64_t nt, const msg::Status& s,
                                              std::uint64_t ns);
[[nodiscard]] std::string monitor_machining_text(const msg::Machining& m);
[[nodiscard]] std::string monitor_advice_text(const msg::Advice& m);

// `robodamp monitor`: joins the domain, shows the cell's topics on `out` as they change (redrawn in place on a
// terminal) and says when the loop falls silent, until Ctrl-C or o.duration_s; the waiting line on `err`.
// 0 when it saw the loop (telemetry or status), 1 when nothing came.
[[nodiscard]] int watch_cell(const dds::ClientOptions& o, std::ostream& out, std::ostream& err);

}  // namespace robodamp::runtime
