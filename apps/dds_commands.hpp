// `robodamp monitor` (a live text view of a running loop from its DDS topics) and `robodamp request`
// (one supervised parameter request and its reply).
#pragma once

#include <optional>
#include <string>

#include "config/supervisory_config.hpp"

namespace robodamp::apps {

struct DdsClientOptions {
  int domain_id{0};
  config::DdsTransport transport{config::DdsTransport::kDefault};
  double duration_s{0.0};  // monitor: 0 = until Ctrl-C; request: how long to wait for the loop and the reply
};

// 0 when it saw the loop (telemetry or status), 1 when nothing came.
[[nodiscard]] int run_monitor(const DdsClientOptions& o);

struct RequestOptions {
  std::optional<double> gain_ns_per_m;
  std::optional<int> parameter_set;
  std::optional<int> enable;
};
// 0 accepted, 3 refused (the reason is printed), 1 no loop or no reply, 2 bad options.
[[nodiscard]] int run_request(const DdsClientOptions& o, const RequestOptions& r);

}  // namespace robodamp::apps
