// `robodamp request`: one supervised parameter request over DDS and its reply.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "apps/cli.hpp"
#include "apps/dds_client.hpp"
#include "dds/participant.hpp"
#include "dds/messages.hpp"
#include "rt/signals.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::apps {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

struct RequestOptions {
  std::optional<double> gain_ns_per_m;
  std::optional<int> parameter_set;
  std::optional<int> enable;
  std::optional<double> spindle_rpm;
  bool reset{false};
};

namespace {
class Replies : public DataReaderListener {
 public:
  Replies(std::string client, std::uint32_t id) : client_(std::move(client)), id_(id) {}
  void on_data_available(DataReader* r) override {
    msg::ParameterReply v;
    SampleInfo info;
    while (r->take_next_sample(&v, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data && v.client() == client_ && v.request_id() == id_) {
        std::lock_guard<std::mutex> lock(m_);
        reply_ = v;
        got_ = true;
      }
  }
  bool get(msg::ParameterReply& out) {
    std::lock_guard<std::mutex> lock(m_);
    out = reply_;
    return got_;
  }

 private:
  std::string client_;
  std::uint32_t id_;
  std::mutex m_;
  msg::ParameterReply reply_;
  bool got_{false};
};
}  // namespace

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
  int rc = 1;
  {
    Replies replies(client, 1);  // before the participant: it outlives the reader that calls it
    dds::Participant p(o.domain_id, o.transport, "robodamp request", o.security);
    DataReader* reader = p.reader(dds::TopicKind::kReply, &replies);
    DataWriter* writer = p.writer(dds::TopicKind::kRequest);
    const auto end = Clock::now() + std::chrono::duration<double>(wait_s);
    // Reliable and volatile: send once the loop's reader and reply writer have matched.
    PublicationMatchedStatus pm;
    SubscriptionMatchedStatus sm;
    while (Clock::now() < end) {
      writer->get_publication_matched_status(pm);
      reader->get_subscription_matched_status(sm);
      if (pm.current_count > 0 && sm.current_count > 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (pm.current_count == 0 || sm.current_count == 0) {
      std::cerr << "robodamp request: no loop on domain " << o.domain_id << " within " << wait_s << " s\n";
      return 1;
    }
    writer->write(&req);
    msg::ParameterReply reply;
    while (Clock::now() < end && !replies.get(reply)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (replies.get(reply)) {
      std::cout << (reply.accepted() ? "accepted: " : "refused: ") << reply.reason() << '\n';
      rc = reply.accepted() ? 0 : 3;
    } else {
      std::cerr << "robodamp request: no reply from cell " << req.cell() << " within " << wait_s << " s\n";
    }
  }
  return rc;
}

void register_request(Registry& r) {
  auto o = std::make_shared<DdsClientArgs>();
  auto req = std::make_shared<RequestOptions>();
  CLI::App* sub =
      r.add("request", "One supervised parameter request over DDS (needs dds.parameter_writes: true)", [o, req] {
        const auto opts = resolve(*o);
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
