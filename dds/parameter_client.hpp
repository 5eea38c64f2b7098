// One supervised parameter request to a cell's loop over DDS and its reply (`robodamp request`, docs/dds.md):
// a participant of its own, the request sent once the loop's reader and reply writer have matched (the
// topics are reliable and volatile: a request written before would be lost), then the reply with the
// request's client and id awaited. Off the real-time path.
#pragma once

#include <optional>

#include "config/supervisory_config.hpp"
#include "dds/messages.hpp"

namespace robodamp::dds {

struct ParameterExchange {
  enum class Outcome {
    kReplied,  // `reply` holds the loop's answer (accepted or refused, with its reason)
    kNoLoop,   // no loop's request reader and reply writer matched within the wait
    kNoReply,  // matched, sent, and no reply to this client and id within the wait
  };
  Outcome outcome{Outcome::kNoLoop};
  msg::ParameterReply reply;
};

// Sends `request` on domain_id (its client and request_id name the reply awaited) and waits at most
// wait_s for the loop to match and then for its reply. Throws std::runtime_error when the participant
// cannot be created (dds/participant.hpp).
[[nodiscard]] ParameterExchange request_parameter(int domain_id, config::DdsTransport transport,
                                                  const std::optional<config::DdsSecurityConfig>& security,
                                                  const msg::ParameterRequest& request, double wait_s);

}  // namespace robodamp::dds
