#include "dds/parameter_client.hpp"

#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "dds/participant.hpp"

namespace robodamp::dds {

namespace {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

// The reply to one client's request, taken on Fast DDS' listener thread.
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
  [[nodiscard]] bool get(msg::ParameterReply& out) {
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

ParameterExchange request_parameter(int domain_id, config::DdsTransport transport,
                                    const std::optional<config::DdsSecurityConfig>& security,
                                    const msg::ParameterRequest& request, double wait_s) {
  ParameterExchange out;
  Replies replies(request.client().c_str(), request.request_id());  // before the participant: it outlives the reader
  Participant p(domain_id, transport, "robodamp request", security);
  DataReader* reader = p.reader(TopicKind::kReply, &replies);
  DataWriter* writer = p.writer(TopicKind::kRequest);
  const auto end = Clock::now() + std::chrono::duration<double>(wait_s);
  PublicationMatchedStatus pm;
  SubscriptionMatchedStatus sm;
  while (Clock::now() < end) {
    writer->get_publication_matched_status(pm);
    reader->get_subscription_matched_status(sm);
    if (pm.current_count > 0 && sm.current_count > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (pm.current_count == 0 || sm.current_count == 0) return out;
  msg::ParameterRequest sent = request;
  writer->write(&sent);
  while (Clock::now() < end && !replies.get(out.reply)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  out.outcome = replies.get(out.reply) ? ParameterExchange::Outcome::kReplied : ParameterExchange::Outcome::kNoReply;
  return out;
}

}  // namespace robodamp::dds
