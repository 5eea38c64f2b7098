// `robodamp request`: one supervised parameter request over DDS and its reply.
#include <unistd.h>

#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "apps/dds_client.hpp"
#include "dds/messages.hpp"
#include "dds/parameter_client.hpp"

namespace robodamp::apps {

struct RequestOptions {
  std::optional<double> gain_ns_per_m;
  std::optional<int> parameter_set;
  std::optional<int> enable;
  std::optional<double> spindle_rpm;
  bool reset{false};
};

// 0 accepted, 3 refused (the reason is printed), 1 no loop or no reply, 2 bad options.
int run_request(const DdsClientOptions& o, const RequestOptions& r) {
  const int given = (r.gain_ns_per_m ? 1 : 0) + (r.parameter_set ? 1 : 0) + (r.enable ? 1 : 0) +
                    (r.spindle_rpm ? 1 : 0) + (r.reset ? 1 : 0);
  if (given != 1) {
    std::cerr << "robodamp request: give exactly one of --gain, --select, --enable, --spindle-rpm, --reset\n";
    return 2;
  }
  msg::ParameterRequest req;
  const std::string client = "robodamp-request-" + std::to_string(getpid());
  req.client(client);
  req.cell(o.cell.empty() ? config::cell_name({}) : o.cell);
  if (r.reset) req.kind(msg::RESET_FAULT), req.value(0.0);
  req.request_id(1);
  if (r.gain_ns_per_m) req.kind(msg::SET_GAIN), req.value(*r.gain_ns_per_m);
  if (r.parameter_set) req.kind(msg::SELECT_PARAMETER_SET), req.value(*r.parameter_set);
  if (r.enable) req.kind(msg::ENABLE), req.value(*r.enable);
  if (r.spindle_rpm) req.kind(msg::SET_SPINDLE_RPM), req.value(*r.spindle_rpm);
  const double wait_s = o.duration_s > 0.0 ? o.duration_s : 10.0;
  const dds::ParameterExchange x = dds::request_parameter(o.domain_id, o.transport, o.security, req, wait_s);
  switch (x.outcome) {
    case dds::ParameterExchange::Outcome::kReplied:
      std::cout << (x.reply.accepted() ? "accepted: " : "refused: ") << x.reply.reason() << '\n';
      return x.reply.accepted() ? 0 : 3;
    case dds::ParameterExchange::Outcome::kNoLoop:
      std::cerr << "robodamp request: no loop on domain " << o.domain_id << " within " << wait_s << " s\n";
      return 1;
    case dds::ParameterExchange::Outcome::kNoReply:
      std::cerr << "robodamp request: no reply from cell " << req.cell() << " within " << wait_s << " s\n";
      return 1;
  }
  return 1;
}

void register_request(Registry& r) {
  auto o = std::make_shared<DdsClientArgs>();
  auto req = std::make_shared<RequestOptions>();
  CLI::App* sub =
      r.add("request", "One supervised parameter request over DDS (needs dds.parameter_writes: true)", [o, req] {
        const auto opts = dds::resolve(*o, std::cerr);
        return opts ? run_request(*opts, *req) : 2;
      });
  add_dds_options(r, sub, *o);
  r.number(sub, "--gain", req->gain_ns_per_m, {"N s/m", 0.0, 1e6},
           "Set the gain K, N s/m (the loop checks it against its own limit)");
  r.whole_number(sub, "--select", req->parameter_set,
                 {"(parameter set)", 0, 255, false, false, "0 = the configuration's own"}, "Select a parameter set");
  r.whole_number(sub, "--enable", req->enable, {"(1 = arm, 0 = disarm)", 0, 1}, "1 = arm, 0 = disarm");
  r.number(sub, "--spindle-rpm", req->spindle_rpm, {"rpm", 0.0, 200000.0},
           "The spindle speed the harmonic notches follow (0 = stopped; the loop checks spindle.rpm_max)");
  sub->add_flag("--reset", req->reset, "Reset a latched trip (the loop is then disabled: arm it with --enable 1)");
  r.number(sub, "--timeout", o->options.duration_s, {"s", 0.1, 3600.0},
           "Wait this long for the loop and the reply (default 10 s)");
}

}  // namespace robodamp::apps
